"""Which layers a costmap has and in what order (Nav2's ``plugins`` list): layer names -> factories, and parameters.

Adding a layer is one class (a ``costmap.layer.Layer``) and one line in ``PLUGINS``; list its name in
``CostmapParams.plugins`` (a scenario file's ``layers.plugins``) where it belongs in the order.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace

from costmap.grid import GridSpec
from costmap.layer import Layer
from costmap.layered import LayeredCostmap
from costmap.layers.inflation import InflationLayer, InflationParams
from costmap.layers.obstacle import ObstacleLayer, ObstacleParams
from costmap.layers.social import SocialLayer, SocialParams
from costmap.layers.static import StaticLayer
from costmap.layers.tracked import TrackedPeopleLayer, TrackedPeopleParams
from costmap.occupancy import OccupancyGrid

__all__ = ["CostmapParams", "Factory", "LayerContext", "PEOPLE_LAYERS", "PLUGINS", "layered_costmap"]


@dataclass(frozen=True)
class CostmapParams:
    """Parameters of the costmap (a scenario file's optional "layers" block): the layers' names in combination
    order and each kind of layer's parameters. The LiDAR layer (``lidar``) reads ``obstacle``."""

    plugins: tuple[str, ...] = ("static", "lidar", "social", "inflation")
    obstacle: ObstacleParams = field(default_factory=ObstacleParams)
    inflation: InflationParams = field(default_factory=InflationParams)
    social: SocialParams = field(default_factory=SocialParams)
    tracked_people: TrackedPeopleParams = field(default_factory=TrackedPeopleParams)

    def __post_init__(self) -> None:
        object.__setattr__(self, "plugins", tuple(self.plugins))
        if len(set(self.plugins)) != len(self.plugins):
            raise ValueError(f"plugins: a layer is listed twice in {list(self.plugins)}")

    def without(self, *names: str) -> CostmapParams:
        """These parameters with the named layers left out (e.g. ``without("social")``: no recognition)."""
        return replace(self, plugins=tuple(name for name in self.plugins if name not in names))


@dataclass(frozen=True)
class LayerContext:
    """What a layer factory may use: the grid, the parameters, the robot's and a person's radius (m), the static map."""

    spec: GridSpec
    params: CostmapParams
    robot_radius: float
    body_radius: float
    static_map: OccupancyGrid | None

    @property
    def people_clear_radius(self) -> float:
        """Radius (m) around a person within which LiDAR marks are the person's own: 0 unless a layer of
        ``PEOPLE_LAYERS`` draws the people."""
        if PEOPLE_LAYERS.isdisjoint(self.params.plugins):
            return 0.0
        return self.body_radius + self.params.social.people_clear_margin


Factory = Callable[[LayerContext], Layer | None]  # None: nothing to add (the static layer without a map)


def _static(c: LayerContext) -> StaticLayer | None:
    return None if c.static_map is None else StaticLayer(c.spec, c.static_map, c.params.obstacle.track_unknown_space)


PLUGINS: dict[str, Factory] = {
    "static": _static,
    "lidar": lambda c: ObstacleLayer(c.spec, c.params.obstacle, c.people_clear_radius),
    "social": lambda c: SocialLayer(c.spec, c.params.social, c.body_radius),
    "tracked_people": lambda c: TrackedPeopleLayer(c.spec, c.params.tracked_people, c.body_radius, c.params.social),
    "inflation": lambda c: InflationLayer(c.spec, c.params.inflation, c.robot_radius),
}

# Layers that draw the people themselves, so their LiDAR marks are cleared.
PEOPLE_LAYERS = frozenset({"social", "tracked_people"})


def layered_costmap(
    spec: GridSpec,
    params: CostmapParams | None = None,
    *,
    robot_radius: float = 0.25,
    body_radius: float = 0.2,
    static_map: OccupancyGrid | None = None,
    plugins: Mapping[str, Factory] = PLUGINS,
) -> LayeredCostmap:
    """The costmap of ``params.plugins``, each layer made by its factory in ``plugins`` and named after it.

    ``robot_radius`` (m) is the inflation's inscribed radius; ``body_radius`` (m) a person's body in the scan plane.
    """
    params = params or CostmapParams()
    unknown = [name for name in params.plugins if name not in plugins]
    if unknown:
        raise ValueError(f"plugins: unknown layer {unknown[0]!r}; known layers: {', '.join(plugins)}")
    context = LayerContext(spec, params, float(robot_radius), float(body_radius), static_map)
    layers = []
    for name in params.plugins:
        layer = plugins[name](context)
        if layer is not None:
            layer.name = name
            layers.append(layer)
    return LayeredCostmap(spec, layers, params.obstacle.default_value)
