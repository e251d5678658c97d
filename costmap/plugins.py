"""Which layers a costmap has and in what order (Nav2's ``plugins`` list): layer instances, their plugins
(factories) and parameters.

As in Nav2, a costmap lists layer instances by name; each has a plugin (the kind of layer, a key of ``PLUGINS``)
and its own parameters. A name that is itself a plugin (``lidar``, ``social``, ...) is an instance of that plugin
with the costmap's parameters for it (``CostmapParams.obstacle`` for ``lidar``, ...); any other name is declared in
``CostmapParams.instances`` (a scenario file's ``layers.NAME: {plugin: lidar, ...}``), so that two LiDAR layers
with different ranges can sit in one costmap. Two settings of the whole costmap come from the listed instances
(``CostmapParams.shared``), which must agree on them: the LiDAR layers' ``track_unknown_space`` (the master's default
value and the static layer's unknown cells) and the social layers' ``people_clear_margin``.

Adding a kind of layer is one class (a ``costmap.layer.Layer``), one line in ``PLUGINS`` and, when it has
parameters, one in ``SECTIONS``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

from costmap.grid import GridSpec
from costmap.layer import Layer
from costmap.layered import LayeredCostmap
from costmap.layers.inflation import InflationLayer, InflationParams
from costmap.layers.obstacle import ObstacleLayer, ObstacleParams
from costmap.layers.social import SocialLayer, SocialParams
from costmap.layers.static import StaticLayer
from costmap.layers.tracked import TrackedPeopleLayer, TrackedPeopleParams
from costmap.occupancy import OccupancyGrid
from sid.errors import InputError

__all__ = [
    "CostmapParams",
    "Factory",
    "LayerContext",
    "LayerInstance",
    "PEOPLE_LAYERS",
    "PLUGINS",
    "SECTIONS",
    "layered_costmap",
]


@dataclass(frozen=True)
class LayerInstance:
    """One named layer of a costmap: its ``plugin`` (a key of ``PLUGINS``) and its own ``params`` (that plugin's
    parameter record, e.g. ``ObstacleParams`` for ``lidar``; None: the costmap's section for the plugin)."""

    plugin: str
    params: Any = None


@dataclass(frozen=True)
class CostmapParams:
    """Parameters of the costmap (a scenario file's optional "layers" block): the layer instances' names in
    combination order, the instances named otherwise than their plugin (``instances``), and each plugin's default
    parameters (the ``lidar`` plugin's are ``obstacle``, as Nav2's obstacle layer)."""

    plugins: tuple[str, ...] = ("static", "lidar", "social", "inflation")
    obstacle: ObstacleParams = field(default_factory=ObstacleParams)
    inflation: InflationParams = field(default_factory=InflationParams)
    social: SocialParams = field(default_factory=SocialParams)
    tracked_people: TrackedPeopleParams = field(default_factory=TrackedPeopleParams)
    instances: Mapping[str, LayerInstance] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "plugins", tuple(self.plugins))
        if len(set(self.plugins)) != len(self.plugins):
            raise InputError(f"plugins: a layer is listed twice in {list(self.plugins)}")
        object.__setattr__(self, "instances", dict(self.instances))
        for name, instance in self.instances.items():
            if not isinstance(instance, LayerInstance):
                raise InputError(f"instances: {name} must be a LayerInstance, got {type(instance).__name__}")
            section = SECTIONS.get(instance.plugin)
            wanted = None if section is None else type(getattr(self, section))
            known = instance.plugin in PLUGINS  # another plugin (``layered_costmap``'s ``plugins``) takes any params
            if known and instance.params is not None and not isinstance(instance.params, wanted or type(None)):
                expected = "None (it takes no parameters)" if wanted is None else f"{wanted.__name__} or None"
                raise InputError(
                    f"instances: {name}'s params must be {expected} for the {instance.plugin} plugin, got "
                    f"{type(instance.params).__name__}"
                )
        self.shared("lidar", "track_unknown_space")
        self.shared("social", "people_clear_margin")

    def shared(self, plugin: str, name: str) -> Any:
        """The parameter ``name`` that the listed instances of ``plugin`` hold, for a setting of the whole costmap
        taken from a layer's (the master's and the static layer's unknown space from the LiDAR layers'
        ``track_unknown_space``, the people's clearing radius from the social layers'); the plugin's section's value
        when none is listed. ValueError naming the instances when they disagree (checked when the record is made)."""
        values = {layer: getattr(self.layer_params(layer), name) for layer in self.named(plugin)}
        if len(set(values.values())) > 1:
            given = ", ".join(f"{layer} {value}" for layer, value in values.items())
            raise InputError(
                f"plugins: the {plugin} layers disagree on {name} ({given}); it sets the whole costmap, so give them "
                "the same value"
            )
        return next(iter(values.values()), getattr(getattr(self, SECTIONS[plugin]), name))

    def plugin(self, name: str) -> str:
        """The plugin of the layer instance ``name``: its declared one, else the name itself."""
        instance = self.instances.get(name)
        return name if instance is None else instance.plugin

    def layer_params(self, name: str) -> Any:
        """The parameters of the layer instance ``name``: its own, else its plugin's section (None: the plugin has
        none, or is not one of ``SECTIONS``)."""
        instance = self.instances.get(name)
        if instance is not None and instance.params is not None:
            return instance.params
        section = SECTIONS.get(self.plugin(name))
        return None if section is None else getattr(self, section)

    def named(self, plugin: str) -> list[str]:
        """The listed layer instances of ``plugin``, in order."""
        return [name for name in self.plugins if self.plugin(name) == plugin]

    def without(self, *names: str) -> CostmapParams:
        """These parameters with the named layers left out (e.g. ``without("social")``: no recognition)."""
        return replace(self, plugins=tuple(name for name in self.plugins if name not in names))


@dataclass(frozen=True)
class LayerContext:
    """What a layer factory may use: the grid, the costmap's parameters, the robot's and a person's radius (m), the
    static map, and the parameters of the layer instance being made (``CostmapParams.layer_params``)."""

    spec: GridSpec
    params: CostmapParams
    robot_radius: float
    body_radius: float
    static_map: OccupancyGrid | None
    layer_params: Any = None

    @property
    def people_clear_radius(self) -> float:
        """Radius (m) around a person within which LiDAR marks are the person's own: 0 unless a layer whose plugin
        is one of ``PEOPLE_LAYERS`` draws the people."""
        if PEOPLE_LAYERS.isdisjoint(self.params.plugin(name) for name in self.params.plugins):
            return 0.0
        return self.body_radius + self.params.shared("social", "people_clear_margin")


Factory = Callable[[LayerContext], Layer | None]  # None: nothing to add (the static layer without a map)


def _static(c: LayerContext) -> StaticLayer | None:
    return (
        None
        if c.static_map is None
        else StaticLayer(c.spec, c.static_map, c.params.shared("lidar", "track_unknown_space"))
    )


PLUGINS: dict[str, Factory] = {
    "static": _static,
    "lidar": lambda c: ObstacleLayer(c.spec, c.layer_params, c.people_clear_radius),
    "social": lambda c: SocialLayer(c.spec, c.layer_params, c.body_radius),
    "tracked_people": lambda c: TrackedPeopleLayer(c.spec, c.layer_params, c.body_radius, c.params.social),
    "inflation": lambda c: InflationLayer(c.spec, c.layer_params, c.robot_radius),
}

SECTIONS: dict[str, str] = {
    "lidar": "obstacle",
    "social": "social",
    "tracked_people": "tracked_people",
    "inflation": "inflation",
}
"""Each plugin with parameters -> the ``CostmapParams`` field holding its defaults (and the record's type)."""

# Plugins that draw the people themselves, so their LiDAR marks are cleared.
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
    """The costmap of ``params.plugins``, each layer instance made by its plugin's factory in ``plugins`` with its
    own parameters (``CostmapParams.layer_params``) and named after the instance.

    ``robot_radius`` (m) is the inflation's inscribed radius; ``body_radius`` (m) a person's body in the scan plane.
    """
    params = params or CostmapParams()
    unknown = [name for name in params.plugins if params.plugin(name) not in plugins]
    if unknown:
        raise InputError(f"plugins: unknown layer {params.plugin(unknown[0])!r}; known layers: {', '.join(plugins)}")
    context = LayerContext(spec, params, float(robot_radius), float(body_radius), static_map)
    layers = []
    for name in params.plugins:
        layer = plugins[params.plugin(name)](replace(context, layer_params=params.layer_params(name)))
        if layer is not None:
            layer.name = name
            layers.append(layer)
    return LayeredCostmap(spec, layers, params.shared("lidar", "default_value"))
