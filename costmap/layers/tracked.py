"""The tracked-people layer: the social layer's costs drawn from tracks (the ``TRACKS`` input), not detections.

It reads the tracker's people and groups (``sid.tracking``), so a person missed for a frame, or a facing that jitters,
does not make the costs blink: tracks persist through short misses and their positions and facings are smoothed.

- standing people: as the social layer (``costmap.layers.social``): a LETHAL body and the asymmetric personal-space
  Gaussian along the smoothed facing.
- walking people: the body, and the personal-space Gaussian turned along their velocity with its front stretched
  to ``sigma_front + lookahead * speed``: the cells they are about to cross cost more, as the velocity-scaled
  proxemic costs of ROS's social_navigation_layers do.
- conversations: the social layer's group zone, from the tracked members' positions and the last o-space polygon.
  Walking groups get no zone: their members' stretched costs already cover where they go.

Costs never exceed 252 except the bodies (254), as in the social layer; combined by ``max_nonzero`` likewise.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from costmap.combine import CombinationMethod
from costmap.grid import GridSpec, Window
from costmap.layer import Input, LayerInputs, RepaintedLayer
from costmap.layers.social import SocialParams, repaint, zone_hull
from sid.checks import check_number
from sid.tracking.records import Tracks

__all__ = ["MAX_LOOKAHEAD", "TRACKS", "TrackedPeopleLayer", "TrackedPeopleParams"]

TRACKS: Input[Tracks | None] = Input("tracks", None)
"""The trackers' confirmed people and groups at the frame (world frame; None: no tracker runs): drawn by the
tracked-people layer."""

MAX_LOOKAHEAD = 10.0
"""The longest ``lookahead`` (s): a walker's cost stretched 14 m ahead at 1.4 m/s; beyond it the windows would grow
without bound and say nothing about where a person will be."""


@dataclass(frozen=True)
class TrackedPeopleParams:
    """``lookahead``: seconds of a walker's motion over which its cost is stretched ahead (sigma ahead =
    sigma_front + lookahead * speed, m). The personal-space and zone costs are the social layer's (``SocialParams``).
    """

    lookahead: float = 1.0

    def __post_init__(self) -> None:
        check_number("tracked people layer", "lookahead", self.lookahead, low=0, high=MAX_LOOKAHEAD, unit="seconds")


class TrackedPeopleLayer(RepaintedLayer):
    """Rebuilt from the current tracks at every update (nothing stale is kept); no tracks given: an empty layer.

    ``social``: the costs of people and zones (as the social layer's); ``params``: the walkers' stretch."""

    name = "tracked_people"
    combination: CombinationMethod = "max_nonzero"
    reads = (TRACKS,)

    def __init__(
        self,
        spec: GridSpec,
        params: TrackedPeopleParams | None = None,
        body_radius: float = 0.2,
        social: SocialParams | None = None,
    ) -> None:
        check_number("tracked people layer", "body_radius", body_radius, low=0, low_open=True, unit="metres")
        super().__init__(spec)
        self.params = params or TrackedPeopleParams()
        self.social = social or SocialParams()
        self.body_radius = float(body_radius)
        self._painted: list[Window] = []  # windows holding the cells the last update may have painted

    def update_windows(self, inputs: LayerInputs, changed: Sequence[Window]) -> list[Window]:
        """Repaint the layer for the tracked people and groups of the ``TRACKS`` of ``inputs``; returns the windows of
        the last update's paint (now cleared) and of this one's."""
        tracks = inputs.get(TRACKS)
        people = [] if tracks is None else [p.as_person() for p in tracks.people]
        by_id = {p.id: p for p in people}
        conversations = [] if tracks is None else [g.as_group() for g in tracks.groups if g.kind == "conversation"]
        hulls = [zone_hull(group, by_id) for group in conversations]  # raises on a bad group before any change
        social = self.social
        fronts = []  # each person's sigma_front: a walker's personal space reaches further ahead
        for track in () if tracks is None else tracks.people:
            front = social.sigma_front
            if track.walking:
                by_id[track.id].theta = math.atan2(track.vy, track.vx)
                front += self.params.lookahead * track.speed
            fronts.append(front)
        previous = self._painted
        self._painted = repaint(self.costs, self.spec, previous, hulls, people, social, self.body_radius, fronts)
        return [*previous, *self._painted]
