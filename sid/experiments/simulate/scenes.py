"""The built-in simulation scenes (package data, ``scenes/*.yaml``) and how ``sid simulate`` finds a scene by name or
file. Every scene is a simulation file (``sid.experiments.simulate.world``)."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from sid.errors import InputError
from sid.experiments.simulate.world import SimWorld, load_world

__all__ = ["SCENE_ORDER", "load_scene", "scene_list", "scene_path"]

SCENE_ORDER = ("paper", "pair", "circle4", "circle5", "wall", "walkers", "forming")
"""The built-in scenes, in the order ``--list`` shows them."""


def scene_path(name: str) -> Path:
    """The file of the built-in scene ``name``; ValueError listing the scenes when there is none."""
    if name not in SCENE_ORDER:
        raise InputError(f"unknown built-in scene {name!r}; built-in scenes: {', '.join(SCENE_ORDER)}")
    return Path(str(resources.files("sid.experiments.simulate") / "scenes" / f"{name}.yaml"))


def load_scene(spec: str | Path) -> SimWorld:
    """A built-in scene by name, or a simulation / scenario file by path."""
    if str(spec) in SCENE_ORDER and not Path(spec).is_file():
        return load_world(scene_path(str(spec)))
    if not Path(spec).is_file():
        raise InputError(f"{spec}: neither a built-in scene ({', '.join(SCENE_ORDER)}) nor an existing file")
    return load_world(spec)


def scene_list() -> list[tuple[str, str]]:
    """(name, description) of every built-in scene."""
    return [(name, load_world(scene_path(name)).settings.description) for name in SCENE_ORDER]
