import pytest

from sid.experiments.simulate.scenes import SCENE_ORDER, load_scene, scene_list, scene_path


def test_every_built_in_scene_ships_loads_and_describes_itself():
    listed = scene_list()
    assert [name for name, _ in listed] == list(SCENE_ORDER)
    for name, description in listed:
        assert scene_path(name).is_file() and description
        world = load_scene(name)
        assert world.scenario.name == name and world.scenario.people


def test_moving_scenes_have_walkers_and_the_paper_scene_hides_a_member():
    assert load_scene("walkers").scenario.walks and load_scene("forming").scenario.walks
    paper = load_scene("paper").scenario
    near, far = (p for p in paper.people if p.id in (1, 3))
    # seen from the start (0, 0), member 3 stands about one body width behind member 1's line of sight
    import math

    assert abs(math.atan2(near.y, near.x) - math.atan2(far.y, far.x)) < math.radians(3.0)


def test_an_unknown_scene_names_the_choices(tmp_path):
    with pytest.raises(ValueError, match="built-in scene"):
        load_scene("nowhere")
    with pytest.raises(ValueError, match="paper"):
        scene_path("nowhere")
