"""A parameters file: the group detector's and the trackers' parameters for ``sid detect`` and ``sid track``.

JSON (``.json``) or YAML (any other extension), every block and field optional (the records' defaults otherwise)::

    groups:                  # sid.perception.groups.GroupParams, as a scenario file's groups block
      positions_only_reach: 1.0
    tracking:                # sid.tracking.session.TrackingParams
      tracker: {measurement_sigma: 0.1, timeout: 2.0}   # the people tracker: sid.tracking.tracker.TrackerParams
      groups: {walk_distance: 1.5}                      # the group tracker: sid.tracking.groups.GroupTrackerParams
      max_robot_speed: 2.0                              # what counts as a jump of the robot pose

Units as the records' (metres, radians, seconds). An unknown block or field, or a value of the wrong kind or out of
range, raises ``ScenarioError`` naming the file and the field (``tracking.tracker.timeout: ...``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from sid.documents import load_document, summary
from sid.perception.groups import GroupParams
from sid.scenario.loader import ScenarioError, params_from_dict
from sid.tracking.session import TrackingParams

__all__ = ["ParamsFile", "load_params_file", "params_file_from_dict"]


@dataclass(frozen=True)
class ParamsFile:
    """The parameters a file gives (the records' defaults for what it leaves out)."""

    groups: GroupParams = field(default_factory=GroupParams)
    tracking: TrackingParams = field(default_factory=TrackingParams)


def params_file_from_dict(data: Any) -> ParamsFile:
    """A ParamsFile from a parsed JSON/YAML document (None, an empty file, gives the defaults). ScenarioError naming
    the field."""
    blocks = [f.name for f in fields(ParamsFile)]
    if data is None:
        return ParamsFile()
    if not isinstance(data, dict):
        raise ScenarioError(f"expected a mapping of the blocks {' and '.join(blocks)}, got {summary(data)}")
    unknown = sorted(str(key) for key in data if key not in blocks)
    if unknown:
        raise ScenarioError(f"{unknown[0]}: unknown block; the blocks: {', '.join(blocks)}")
    return ParamsFile(
        **{
            key: params_from_dict(value, key, GroupParams if key == "groups" else TrackingParams)
            for key, value in data.items()
        }
    )


def load_params_file(path: str | Path) -> ParamsFile:
    """Read a parameters file (.json, or YAML for any other suffix); errors (ValueError, ScenarioError) name the
    file and the field."""
    path = Path(path)
    data = load_document(path, "parameters file")
    try:
        return params_file_from_dict(data)
    except ScenarioError as exc:
        raise ScenarioError(f"{path}: {exc}") from exc
