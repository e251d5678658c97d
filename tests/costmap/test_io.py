"""Costmap exports and readers: OccupancyGrid tables, map_server files, .npz, .mcap, pictures and the command."""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np
import pytest
import yaml
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from costmap.export import export_costmap
from costmap.grid import Costmap2D, GridSpec
from costmap.layered import LayeredCostmap
from costmap.layers.social import GROUPS, PEOPLE
from costmap.layers.static import static_costs
from costmap.mapfile import MapFileError, read_map, write_map
from costmap.npz import load_npz, save_npz
from costmap.occupancy import OccupancyGrid, cost_to_occupancy, costmap_to_occupancy, occupancy_to_cost
from costmap.render import GROUP_COLOURS, OBSTACLE, default_scale, render_costmap, world_to_image
from costmap.rosbag import MSGTYPE, _message, read_occupancy_grids, write_occupancy_mcap
from sid.cli import main
from sid.perception.group import Group
from sid.perception.people import Person
from sid.scenario.build import build_costmap
from sid.scenario.loader import load_scenario
from tests.conftest import REPO_ROOT

EXAMPLE = REPO_ROOT / "examples" / "conversation.json"
SPEC = GridSpec(0.05, -1.0, -2.0, 40, 30)


def every_cost_grid() -> Costmap2D:
    """A costmap holding every value 0..255 at least once, in an asymmetric layout (catches flips)."""
    costs = np.zeros(SPEC.shape, dtype=np.uint8)
    costs.ravel()[:256] = np.arange(256)
    return Costmap2D(SPEC, costs)


def example_layered(social: bool = True) -> LayeredCostmap:
    scenario = load_scenario(EXAMPLE)
    groups = [Group((1, 2, 3), (4.0, 0.0), 0.05, np.array([[4.0, 0.2], [3.83, -0.1], [4.17, -0.1]]), 0.6)]
    return build_costmap(scenario, social=social, groups=groups if social else None)


# --- cost <-> OccupancyGrid -------------------------------------------------------------------------------


def test_cost_to_occupancy_is_nav2_publisher_table():
    occ = cost_to_occupancy(np.arange(256, dtype=np.uint8))
    assert occ.dtype == np.int8
    assert (occ[0], occ[253], occ[254], occ[255]) == (0, 99, 100, -1)
    assert occ[1] == 1 and occ[252] == 1 + 97 * 251 // 251 == 98
    assert all(occ[c] == 1 + (97 * (c - 1)) // 251 for c in range(1, 253))
    assert (np.diff(occ[:253].astype(int)) >= 0).all()


def test_occupancy_to_cost_is_nav2_static_layer():
    values = np.array([-1, 0, 50, 98, 99, 100], dtype=np.int8)
    assert occupancy_to_cost(values).tolist() == [255, 0, 0, 0, 253, 254]
    assert occupancy_to_cost(values, trinary=False).tolist() == [255, 0, 127, 248, 253, 254]
    assert occupancy_to_cost(values, track_unknown_space=False)[0] == 0
    # Nav2 reads each value as an unsigned byte: -2 .. -128 are 254 .. 128, lethal (they came out free)
    corrupt = np.array([-2, -50, -128, 101, 127], dtype=np.int8)
    assert occupancy_to_cost(corrupt).tolist() == [254] * 5
    assert occupancy_to_cost(corrupt, trinary=False).tolist() == [254] * 5


# --- map_server files ------------------------------------------------------------------------------------


def test_map_file_round_trip_reproduces_the_occupancy_values_exactly(tmp_path):
    costmap = every_cost_grid()
    image = write_map(tmp_path / "costmap.yaml", costmap_to_occupancy(costmap))
    assert image.name == "costmap.pgm" and image.read_bytes().startswith(b"P5")
    meta = yaml.safe_load((tmp_path / "costmap.yaml").read_text())
    assert meta["mode"] == "raw" and meta["image"] == "costmap.pgm" and meta["origin"] == [-1.0, -2.0, 0.0]
    loaded = read_map(tmp_path / "costmap.yaml")
    assert loaded.spec == costmap.spec
    np.testing.assert_array_equal(loaded.data, cost_to_occupancy(costmap.costs))


def test_map_file_image_top_row_is_the_highest_y(tmp_path):
    grid = OccupancyGrid(SPEC, np.zeros(SPEC.shape, dtype=np.int8))
    grid.data[-1, 0] = 100  # highest y, lowest x
    write_map(tmp_path / "m.yaml", grid)
    pixels = cv2.imread(str(tmp_path / "m.pgm"), cv2.IMREAD_UNCHANGED)
    assert pixels[0, 0] == 100 and pixels[-1, 0] == 0


def write_other_tool_map(tmp_path, pixels: np.ndarray, mode: str | None, negate: int = 0, ext: str = "pgm"):
    cv2.imwrite(str(tmp_path / f"other.{ext}"), pixels)
    meta = {
        "image": f"other.{ext}",
        "resolution": 0.1,
        "origin": [1.0, 2.0, 0.0],
        "negate": negate,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    }
    if mode:
        meta["mode"] = mode
    (tmp_path / "other.yaml").write_text(yaml.safe_dump(meta))
    return read_map(tmp_path / "other.yaml")


def test_reads_map_saver_trinary_maps(tmp_path):
    pixels = np.array([[0, 254, 205], [100, 160, 255]], dtype=np.uint8)  # map_saver: 0 occupied, 254 free
    grid = write_other_tool_map(tmp_path, pixels, None)
    # p = 1 - pixel/255: 1.0 -> 100, 0.004 -> 0, 0.196 -> unknown (strict thresholds), 0.61 -> unknown
    assert grid.data.tolist() == [[-1, -1, 0], [100, 0, -1]]  # rows flipped: image top = highest y
    assert (grid.spec.width, grid.spec.height, grid.spec.origin_x) == (3, 2, 1.0)
    negated = write_other_tool_map(tmp_path, pixels, "trinary", negate=1)
    assert negated.data.tolist() == [[-1, -1, 100], [0, 100, 100]]  # p = pixel / 255


@pytest.mark.parametrize(("maxval", "dtype"), [(15, ">u1"), (1, ">u1"), (1000, ">u2")])
def test_pgm_maps_are_scaled_by_their_declared_maximum(tmp_path, maxval, dtype):
    # Free, occupied and mid-grey pixels at a maximum other than 255 / 65535 (map_server scales by the header's).
    pixels = np.array([[maxval, 0, maxval // 2]], dtype=dtype)
    (tmp_path / "other.pgm").write_bytes(b"P5\n# a comment\n3 1\n%d\n" % maxval + pixels.tobytes())
    meta = {"image": "other.pgm", "resolution": 0.1, "origin": [0.0, 0.0, 0.0], "negate": 0}
    (tmp_path / "other.yaml").write_text(yaml.safe_dump(meta | {"occupied_thresh": 0.65, "free_thresh": 0.196}))
    expected = [0, 100, -1] if maxval > 1 else [0, 100, 100]  # maximum 1: no grey, 1 // 2 = 0 is black
    assert read_map(tmp_path / "other.yaml").data.tolist() == [expected]


def test_reads_scale_maps_with_transparency(tmp_path):
    bgra = np.zeros((1, 3, 4), dtype=np.uint8)
    bgra[0, :, :3] = np.array([0, 128, 255])[:, None]
    bgra[0, :, 3] = [255, 255, 0]  # last pixel transparent
    grid = write_other_tool_map(tmp_path, bgra, "scale", ext="png")
    p = 1 - 128 / 255
    assert grid.data.tolist() == [[100, int(np.rint((p - 0.196) / (0.65 - 0.196) * 100)), -1]]


def test_reads_raw_maps(tmp_path):
    grid = write_other_tool_map(tmp_path, np.array([[0, 42, 100, 101, 255]], dtype=np.uint8), "raw", negate=1)
    assert grid.data.tolist() == [[0, 42, 100, -1, -1]]


@pytest.mark.parametrize(
    "meta,message",
    [
        ({"image": "x.pgm", "origin": [0, 0, 0]}, "missing key 'resolution'"),
        ({"image": "x.pgm", "resolution": 0, "origin": [0, 0, 0]}, "'resolution' must be positive"),
        ({"image": "x.pgm", "resolution": 0.05, "origin": [0, 0]}, r"'origin' must be \[x, y, yaw\]"),
        ({"image": "x.pgm", "resolution": 0.05, "origin": [0, 0, 0], "mode": "fancy"}, "'mode' must be one of"),
        ({"resolution": 0.05, "origin": [0, 0, 0]}, "'image' must name"),
    ],
)
def test_bad_map_yaml_is_named(tmp_path, meta, message):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump({"negate": 0, "occupied_thresh": 0.65, "free_thresh": 0.25, **meta}))
    with pytest.raises(MapFileError, match=message):
        read_map(path)


def test_missing_map_image_is_named(tmp_path):
    path = tmp_path / "m.yaml"
    write_map(path, OccupancyGrid(SPEC, np.zeros(SPEC.shape, dtype=np.int8)))
    (tmp_path / "m.pgm").unlink()
    with pytest.raises(MapFileError, match="cannot read map image"):
        read_map(path)


def test_static_map_is_resampled_onto_another_grid(tmp_path):
    data = np.zeros((10, 10), dtype=np.int8)
    data[5, 5] = 100
    grid = OccupancyGrid(GridSpec(0.1, 0.0, 0.0, 10, 10), data)
    spec = GridSpec(0.05, -0.5, -0.5, 40, 40)
    costs = static_costs(grid, spec)
    lethal = np.argwhere(costs == 254)
    assert len(lethal) == 4  # one 10 cm cell = four 5 cm cells
    assert np.allclose(spec.cell_to_world(lethal).mean(axis=0), [0.55, 0.55])
    assert costs[0, 0] == 255  # outside the static map


@pytest.mark.parametrize("column", [80, 121])
def test_a_thin_wall_of_a_finer_map_stays_on_coarser_cells(column):
    """A one-pixel wall of a 0.025 m map on 0.05 m cells: each cell centre falls on a border between two pixels,
    and sampling under it lost every wall on an even column; the planner drove through it."""
    data = np.zeros((80, 160), dtype=np.int8)
    data[:, column] = 100
    data[10, 10] = -1  # one unknown pixel beside free ones: the cell is free
    data[:2, :2] = -1  # four: the cell is unknown
    grid = OccupancyGrid(GridSpec(0.025, 0.0, 0.0, 160, 80), data)
    costs = static_costs(grid, GridSpec(0.05, 0.0, 0.0, 80, 40))
    assert np.argwhere(costs == 254)[:, 1].tolist() == [column // 2] * 40
    assert costs[5, 5] == 0 and costs[0, 0] == 255


def test_a_map_shifted_by_part_of_a_cell_draws_a_wall_in_both_cells_it_overlaps():
    data = np.zeros((4, 8), dtype=np.int8)
    data[:, 3] = 100  # x 0.175 .. 0.225 m on cells shifted by half a cell
    grid = OccupancyGrid(GridSpec(0.05, 0.025, 0.0, 8, 4), data)
    costs = static_costs(grid, GridSpec(0.05, 0.0, 0.0, 10, 4))
    assert np.argwhere(costs[0] == 254).ravel().tolist() == [3, 4]
    aligned = static_costs(grid, GridSpec(0.05, -0.075, 0.0, 12, 4))  # whole cells apart: taken as it is
    assert np.argwhere(aligned[0] == 254).ravel().tolist() == [5]


# --- npz and mcap -------------------------------------------------------------------------------------------


def test_npz_round_trip_is_exact(tmp_path):
    layered = example_layered()
    saved = load_npz(save_npz(tmp_path / "c.npz", layered))
    assert saved.spec == layered.spec
    np.testing.assert_array_equal(saved.master.costs, layered.master.costs)
    assert list(saved.layers) == ["static", "lidar", "social", "inflation"]  # static: the declared obstacles
    for name, grid in layered.grids.items():
        np.testing.assert_array_equal(saved.layers[name], grid)


def test_npz_errors_name_the_file(tmp_path):
    (tmp_path / "junk.npz").write_bytes(b"junk")
    with pytest.raises(ValueError, match="junk.npz: cannot read"):
        load_npz(tmp_path / "junk.npz")
    np.savez(tmp_path / "other.npz", a=np.zeros(3))
    with pytest.raises(ValueError, match="missing 'costmap'"):
        load_npz(tmp_path / "other.npz")
    grid = dict(layer_names=np.array(["social"]), resolution=np.float64(0.05), origin=np.zeros(2))
    known, unknown = np.zeros((3, 4), np.uint8), np.zeros((3, 4))
    for name, arrays, message in (
        ("float_layer", dict(costmap=known, layer_social=unknown), "social' must be uint8 .*, got float64 \\(3, 4\\)"),
        ("no_layer", dict(costmap=known), "must be uint8 of shape \\(3, 4\\), got missing"),
        ("float_master", dict(costmap=unknown, layer_social=known), "costs must be uint8"),
    ):
        np.savez(tmp_path / f"{name}.npz", **grid, **arrays)
        with pytest.raises(ValueError, match=f"{name}.npz: .*{message}"):
            load_npz(tmp_path / f"{name}.npz")
    np.savez(tmp_path / "flat.npz", **{**grid, "resolution": np.float64(0.0)}, costmap=known)
    with pytest.raises(ValueError, match="flat.npz: map: resolution must be a positive number"):
        load_npz(tmp_path / "flat.npz")


@pytest.mark.parametrize("distro", ["humble", "jazzy"])
def test_mcap_round_trip_is_exact(tmp_path, distro):
    costmap = every_cost_grid()
    social = Costmap2D(SPEC, np.flipud(costmap.costs).copy())
    grids = {"/costmap": costmap_to_occupancy(costmap), "/social_costmap": costmap_to_occupancy(social)}
    path = write_occupancy_mcap(tmp_path / "c.mcap", grids, stamp_ns=1_700_000_000_123, distro=distro)
    assert path.read_bytes()[:8] == b"\x89MCAP0\r\n"
    back = read_occupancy_grids(path)
    assert set(back) == {"/costmap", "/social_costmap"}
    for topic, grid in grids.items():
        (msg,) = back[topic]
        assert msg.spec == grid.spec and msg.frame_id == "map" and msg.origin_yaw == 0.0
        np.testing.assert_array_equal(msg.data, grid.data)
    with pytest.raises(ValueError, match="already exists"):
        write_occupancy_mcap(path, grids)


def test_an_occupancy_grid_message_of_the_wrong_size_names_the_bag_and_the_topic(tmp_path):
    # A real rosbag2 folder (MCAP storage) written with rosbags: one good message, then one whose data is a cell short
    # and one of width 0.
    typestore = get_typestore(Stores.ROS2_HUMBLE)
    good = _message(typestore, costmap_to_occupancy(every_cost_grid()), 0)
    short = dataclasses.replace(good, data=good.data[:-1])
    empty = dataclasses.replace(good, info=dataclasses.replace(good.info, width=0), data=good.data[:0])
    for name, bad, message in (
        ("short", short, rf"/costmap, message 2: data holds {good.data.size - 1} cells, not width x height = "),
        ("empty", empty, r"/costmap, message 2: map: width must be a whole number >= 1, got 0"),
    ):
        with Writer(tmp_path / name, version=8, storage_plugin=StoragePlugin.MCAP) as writer:
            connection = writer.add_connection("/costmap", MSGTYPE, typestore=typestore)
            for stamp, msg in enumerate((good, bad)):
                writer.write(connection, stamp, typestore.serialize_cdr(msg, MSGTYPE))
        with pytest.raises(ValueError, match=rf"{name}: {message}"):
            read_occupancy_grids(tmp_path / name)


# --- pictures and the command -------------------------------------------------------------------------------


def test_world_to_image_puts_y_up_and_x_right():
    scale = 4
    (u0, v0), (u1, v1) = world_to_image([[-1.0, -2.0], [1.0, -0.5]], SPEC, scale)
    assert u1 - u0 == pytest.approx(2.0 / 0.05 * scale) and v0 - v1 == pytest.approx(1.5 / 0.05 * scale)


def test_render_draws_costs_people_and_zones_where_the_world_says():
    layered = example_layered()
    img = render_costmap(layered, scale=3)
    assert img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3
    u, v = world_to_image([[4.0, 0.6]], layered.spec, 3)[0].astype(int)
    assert tuple(img[v, u]) == GROUP_COLOURS[0]  # person 1's disc, in its group's colour (BGR)
    plain = render_costmap(layered.master, scale=3)  # costs only
    lethal = layered.spec.cell_to_world(np.argwhere(layered.master.costs == 254)[:1])
    free = layered.spec.cell_to_world(np.argwhere(layered.master.costs == 0)[:1])
    for xy, colour in ((lethal, (0, 0, 0)), (free, (255, 255, 255))):
        u, v = np.floor(world_to_image(xy, layered.spec, 3)[0]).astype(int)
        assert tuple(plain[v, u]) == colour
    with pytest.raises(ValueError, match="scale"):
        render_costmap(layered, scale=0)


def test_render_draws_outlines_closed_or_open_over_the_costs():
    spec = GridSpec(0.05, 0.0, 0.0, 80, 60)
    costmap = Costmap2D.filled(spec, 0)
    costmap.costs[20:41, 20:41] = 254  # the box's cells: the outline is drawn over them too
    box = np.array([[1.0, 1.0], [2.0, 1.0], [2.0, 2.0], [1.0, 2.0]])
    wall = np.array([[0.5, 0.5], [3.5, 0.5], [3.5, 2.5]])
    img = render_costmap(costmap, scale=3, outlines=[(box, True), (wall, False)])

    def drawn(points) -> np.ndarray:
        uv = np.rint(world_to_image(np.asarray(points, dtype=float), spec, 3)).astype(int)
        return np.array([tuple(img[v, u]) == OBSTACLE for u, v in uv])

    t = np.linspace(0.05, 0.95, 19)[:, None]
    for a, b in zip(box, np.roll(box, -1, axis=0), strict=True):  # every side, the closing one included
        assert drawn(a + t * (b - a)).all()
    assert drawn(wall[0] + t * (wall[1] - wall[0])).all() and drawn(wall[1] + t * (wall[2] - wall[1])).all()
    assert not drawn(wall[2] + t[:6] * (wall[0] - wall[2])).any()  # an open polyline stays open
    assert not drawn([[1.5, 1.5], [0.2, 2.8]]).any()


def test_export_writes_every_file_and_they_read_back(tmp_path):
    layered = example_layered()
    paths = export_costmap(layered, tmp_path / "out", stamp_ns=0)
    assert {p.name for p in paths.values()} == {
        "costmap.yaml",
        "costmap.pgm",
        "costmap.npz",
        "costmap.mcap",
        "costmap.png",
    }
    np.testing.assert_array_equal(read_map(paths["yaml"]).data, cost_to_occupancy(layered.master.costs))
    bag = read_occupancy_grids(paths["mcap"])
    np.testing.assert_array_equal(bag["/social_costmap"][0].data, cost_to_occupancy(layered.grids["social"]))
    assert cv2.imread(str(paths["png"])).shape[0] > 400


@pytest.mark.slow
def test_sid_costmap_command(tmp_path, capsys):
    assert main(["costmap", str(EXAMPLE), "--out", str(tmp_path), "--no-social"]) == 0
    out = capsys.readouterr().out
    assert "without recognition" in out and "costmap.mcap" in out
    assert set(read_occupancy_grids(tmp_path / "costmap.mcap")) == {"/costmap"}
    saved = load_npz(tmp_path / "costmap.npz")
    assert "social" not in saved.layers
    # The picture draws the declared box (7..8, 1.6..2.4) whole, also the far faces the scan from (0, 0) never hits.
    img = cv2.imread(str(tmp_path / "costmap.png"))
    spec = load_scenario(EXAMPLE).grid
    scale = default_scale(spec)
    t = np.linspace(0.05, 0.95, 19)[:, None]
    for a, b in (((8.0, 1.6), (8.0, 2.4)), ((7.0, 2.4), (8.0, 2.4))):
        uv = np.rint(world_to_image(np.array(a) + t * (np.array(b) - np.array(a)), spec, scale)).astype(int)
        assert all(tuple(img[v, u]) == OBSTACLE for u, v in uv)


def test_sid_costmap_reports_a_bad_scenario(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text('{"map": {"size": [2, 2]}, "robot": {"start": [0, 0], "goal": [5, 5]}}')
    assert main(["costmap", str(bad), "--out", str(tmp_path / "out")]) == 2
    assert "robot.goal" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_people_without_recognition_are_only_lidar_obstacles():
    layered = example_layered(social=False)
    assert set(layered.grids) == {"static", "lidar", "inflation"} and layered.inputs[GROUPS] == ()
    assert isinstance(layered.inputs[PEOPLE][0], Person)
