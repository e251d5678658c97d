"""The one place where layers are combined (Nav2's LayeredCostmap).

Order and combination, as in a Nav2 global costmap: the master grid is reset to NO_INFORMATION (or FREE when
unknown space is not tracked); the static map is written with true overwrite; the LiDAR layer with max; the
social layer with max; the inflation layer last, from the lethal cells of the result (max, with Nav2's rule that
only costs >= 253 replace unknown cells). The social layer's zero cells carry no opinion: they are left out of the
max, as cells outside a Nav2 layer's update bounds are, so unknown space stays unknown around people.

People and their LiDAR marks. A robot without recognition (``social=False``) sees people only as LiDAR marks,
kept and cleared by ray tracing like any obstacle. With recognition, the social layer owns the people: at each
update, (1) LiDAR marks within ``body_radius + people_clear_margin`` of the people's previous positions are
cleared before the new scan is applied (so a person who moved leaves nothing behind, even where no new beam
reaches), (2) the new scan clears and marks, (3) marks around the current people are cleared and (4) the social
layer, rebuilt from scratch, draws each body as LETHAL plus its zones. A person is therefore counted once, at its
current position; a mark at an old position that the new scan hits again stays (something is really there).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from costmap.combine import update_with_max, update_with_true_overwrite
from costmap.grid import FREE_SPACE, Costmap2D, GridSpec
from costmap.layers.inflation import InflationLayer, InflationParams
from costmap.layers.obstacle import ObstacleLayer, ObstacleParams
from costmap.layers.social import SocialLayer, SocialParams
from costmap.scan import LaserScan
from sid.perception.groups import Group
from sid.perception.people import Person


@dataclass(frozen=True)
class CostmapParams:
    """Parameters of the costmap layers (a scenario file's optional "layers" block)."""

    obstacle: ObstacleParams = field(default_factory=ObstacleParams)
    inflation: InflationParams = field(default_factory=InflationParams)
    social: SocialParams = field(default_factory=SocialParams)


def _check_people(people: Sequence[Person]) -> list[Person]:
    seen = set()
    for p in people:
        if not (np.isfinite(p.x) and np.isfinite(p.y)) or (p.theta is not None and not np.isfinite(p.theta)):
            raise ValueError(f"person {p.id}: pose must be finite, got x={p.x}, y={p.y}, theta={p.theta}")
        if p.id in seen:
            raise ValueError(f"person id {p.id} appears twice")
        seen.add(p.id)
    return list(people)


class LayeredCostmap:
    """A master grid and its layers: optional static map, LiDAR, social (optional) and inflation.

    ``robot_radius`` (m) is the inflation's inscribed radius; ``body_radius`` (m) a person's body in the scan
    plane. Call ``update`` once per frame with the people and groups (world frame) and, when there is one, a scan.
    """

    def __init__(
        self,
        spec: GridSpec,
        params: CostmapParams | None = None,
        *,
        robot_radius: float = 0.25,
        body_radius: float = 0.2,
        social: bool = True,
        static: np.ndarray | None = None,
    ) -> None:
        self.spec = spec
        self.params = params or CostmapParams()
        self.body_radius = float(body_radius)
        if static is not None and (static.dtype != np.uint8 or static.shape != spec.shape):
            raise ValueError(f"static layer must be uint8 of shape {spec.shape}, got {static.dtype} {static.shape}")
        self.static = static
        self.lidar = ObstacleLayer(spec, self.params.obstacle)
        self.social = SocialLayer(spec, self.params.social, body_radius) if social else None
        self.inflation = InflationLayer(spec, self.params.inflation, inscribed_radius=robot_radius)
        self.master = Costmap2D.filled(spec, self.params.obstacle.default_value)
        self.people: list[Person] = []
        self.groups: list[Group] = []
        self.scan: LaserScan | None = None

    @property
    def layers(self) -> dict[str, np.ndarray]:
        """Each layer's own uint8 grid, in combination order."""
        out = {} if self.static is None else {"static": self.static}
        out["lidar"] = self.lidar.costs
        if self.social is not None:
            out["social"] = self.social.costs
        out["inflation"] = self.inflation.costs
        return out

    @property
    def people_clear_radius(self) -> float:
        """Radius (m) around a tracked person within which LiDAR marks are the person's own."""
        return 0.0 if self.social is None else self.social.body_radius + self.params.social.people_clear_margin

    def update(self, people: Sequence[Person], groups: Sequence[Group], scan: LaserScan | None = None) -> None:
        """Bring every layer to the current people, groups and (optional) scan, then recombine the master."""
        people = _check_people(people)
        if scan is not None and not self.spec.contains([scan.pose[:2]])[0]:  # checked before anything changes
            raise ValueError(f"scan: sensor at ({scan.pose[0]:.2f}, {scan.pose[1]:.2f}) is outside the costmap")
        if self.social is not None:
            self.lidar.clear_discs([(p.x, p.y) for p in self.people], self.people_clear_radius)
        if scan is not None:
            self.lidar.apply_scan(scan)
            self.scan = scan
        if self.social is not None:
            self.lidar.clear_discs([(p.x, p.y) for p in people], self.people_clear_radius)
            self.social.update(people, groups)
        self.people, self.groups = people, list(groups)
        self._combine()

    def _combine(self) -> None:
        master = self.master.costs
        master.fill(self.params.obstacle.default_value)
        if self.static is not None:
            update_with_true_overwrite(master, self.static)
        update_with_max(master, self.lidar.costs)
        if self.social is not None:
            update_with_max(master, self.social.costs, no_opinion=FREE_SPACE)
        self.inflation.apply(master)
