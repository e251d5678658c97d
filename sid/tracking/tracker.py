"""Multi-person tracking on the ground plane: stable ids, constant-velocity motion, standing / walking.

Per frame (``PeopleTracker.update``): every track is predicted to the frame's timestamp (``sid.tracking.motion``);
tracks undetected for longer than ``out_of_view_timeout`` are deleted; detections are
assigned to tracks by position alone, the least total distance to the predictions within a gate that grows with the
track's uncertainty (``sid.tracking.assignment``); matched tracks are corrected; a track missed in a frame that comes
more than ``timeout`` after its last detection, counting only time in the camera's view (time out of it or behind
someone detected nearer to the camera does not count: nobody looked there), is deleted, as is a tentative track that
is missed, and one detected ``confirm_hits`` times (or twice in a row ``confirm_time`` apart) is confirmed; every
unmatched detection starts a tentative track. Facing is smoothed on the circle (an exponential average of unit
vectors, a new one weighted by the time since the track's last measured facing), and the state switches to
walking above ``walk_speed`` and back to standing below ``stand_speed``.

Only confirmed tracks are reported. Track ids count up from 1 and are never reused, also across ``reset``.
"""

from __future__ import annotations

import math
import numbers
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from sid.checks import MAX_COORDINATE, YAW_LIMIT_RAD, check_number, check_numbers, check_whole, check_yaws, is_real
from sid.documents import InputWarning
from sid.errors import SidError
from sid.perception.people import Person
from sid.tracking.assignment import gated_assignment
from sid.tracking.motion import MotionStates
from sid.tracking.records import TIME_TOLERANCE, TrackedPerson
from sid.tracking.view import View, ViewCone

__all__ = [
    "OCCLUDER_RADIUS",
    "PeopleTracker",
    "TimeGapWarning",
    "TrackerParams",
    "TrackingError",
    "check_people",
    "check_time_order",
]

OCCLUDER_RADIUS = 0.2
"""A person's half-width (m) seen from above, to tell who is behind whom in the camera's view (``ViewCone.behind``)."""


class TrackingError(SidError, ValueError):
    """Input a tracker cannot use: a frame out of time order, a non-finite position, an id given twice."""


class TimeGapWarning(InputWarning):
    """Frames further apart than the tracker's timeout ended its tracks: said once for such frames in a row, since
    timestamps in milli- or nanoseconds make every frame one and nobody is ever reported."""


def check_time_order(what: str, timestamp: float, last: float | None) -> None:
    """Raise TrackingError unless ``timestamp`` (s) is finite and after ``last`` (s; None: there was no frame before),
    as every tracker requires; ``what`` names the input in the message."""
    check_number(what, "timestamp", timestamp, unit="seconds", error=TrackingError)
    if last is not None and timestamp <= last:
        raise TrackingError(
            f"{what} is out of time order: its timestamp {timestamp} s is not after the last one, {last} s"
        )


@dataclass(frozen=True)
class TrackerParams:
    """Parameters of ``PeopleTracker`` (metres, seconds, m/s; measured in docs/tracking.md).

    measurement_sigma: noise of a detected position (m), per axis. acceleration_sigma: how hard people change
    velocity (m/s^2, white-noise acceleration). initial_speed_sigma: the velocity uncertainty of a new track (m/s).
    gate_sigmas, min_gate, max_gate: a detection may join a track when it lies within gate_sigmas standard
    deviations of the prediction, bounded to [min_gate, max_gate] (m); max_speed: the fastest a person is followed
    (m/s): a new track (its velocity unknown) takes a detection up to max_speed x the time between the frames away
    when that is more than max_gate (at frames more than max_gate / max_speed, 0.4 s, apart).
    confirm_hits: detections that confirm a track; confirm_time: two detections in a row at least this far apart (s)
    confirm it too, so that a slow detector (a few Hz) does not hold a person back for confirm_hits long frames.
    timeout: a confirmed track missed in a frame more than this (s) after its last detection, counting time in the
    camera's view only (not behind someone detected nearer to it), is deleted (a detection in that frame still
    continues it: a slow detector's frames may come further apart); out_of_view_timeout: seconds it survives
    undetected in all. walk_speed, stand_speed: speeds (m/s)
    above which a standing track walks and below which a walking track stands (hysteresis). facing_tau: time
    constant (s) of the facing average. heading_gate: a walking track faster than walk_speed, missed in the last
    frame, takes no detection facing more than this (rad) away from its own facing (its velocity while it has none).
    """

    measurement_sigma: float = 0.15
    acceleration_sigma: float = 0.3
    initial_speed_sigma: float = 1.0
    gate_sigmas: float = 3.0
    min_gate: float = 0.5
    max_gate: float = 1.0
    max_speed: float = 2.5
    confirm_hits: int = 3
    confirm_time: float = 0.2
    timeout: float = 1.5
    out_of_view_timeout: float = 4.0
    walk_speed: float = 0.5
    stand_speed: float = 0.3
    facing_tau: float = 0.3
    heading_gate: float = 2.0

    def __post_init__(self) -> None:
        positive = ("measurement_sigma", "acceleration_sigma", "initial_speed_sigma", "gate_sigmas", "min_gate")
        check_numbers("tracker", self, positive, low=0, low_open=True)
        check_number("tracker", "max_gate", self.max_gate, low=self.min_gate, unit="metres")
        seconds = ("confirm_time", "timeout", "out_of_view_timeout", "facing_tau")
        check_numbers("tracker", self, seconds, low=0, unit="seconds")
        check_number("tracker", "heading_gate", self.heading_gate, low=0, high=math.pi, low_open=True, unit="radians")
        check_number("tracker", "walk_speed", self.walk_speed, low=0, low_open=True, unit="m/s")
        check_number("tracker", "max_speed", self.max_speed, low=0, unit="m/s")
        check_number("tracker", "stand_speed", self.stand_speed, low=0, high=self.walk_speed, unit="m/s")
        check_whole("tracker", "confirm_hits", self.confirm_hits, low=1)


class PeopleTracker:
    """Tracks people across frames (positions in one fixed frame, e.g. the map). State lives between calls."""

    def __init__(self, params: TrackerParams | None = None) -> None:
        self.params = params or TrackerParams()
        self._next_id = 1
        self.reset()

    def reset(self) -> None:
        """Forget every track and the last timestamp (ids keep counting up)."""
        self._time: float | None = None
        self._motion = MotionStates()
        self._ids = np.zeros(0, dtype=np.int64)
        self._hits = np.zeros(0, dtype=np.int64)
        self._confirmed = np.zeros(0, dtype=bool)
        self._walking = np.zeros(0, dtype=bool)
        self._last_hit = np.zeros(0)
        self._unseen = np.zeros(0)  # seconds undetected since the last hit while the camera could see the track
        self._first_hit = np.zeros(0)
        self._facing = np.zeros((0, 2))  # exponential averages of unit facing vectors (length <= 1), NaN: unknown
        self._facing_time = np.zeros(0)  # timestamp (s) of the last measured facing, NaN while unknown
        self._quality = np.zeros(0)  # the facing's orientation quality in [0, 1], averaged as it; NaN while unknown
        self._detection = np.zeros(0, dtype=np.intp)  # index of this frame's matched detection, -1: none
        self._in_view = np.zeros(0, dtype=bool)  # the predicted position lies in the camera's view
        self._gap_in_a_row = False  # the last frame came more than the timeout after the one before it

    @property
    def timestamp(self) -> float | None:
        """Timestamp (s) of the last update, None before the first or after a reset."""
        return self._time

    def __len__(self) -> int:
        """Tracks held, tentative ones included."""
        return len(self._ids)

    def update(self, people: Sequence[Person], timestamp: float, view: View | None = None) -> list[TrackedPerson]:
        """Bring the tracks to the frame at ``timestamp`` (s) with its detected ``people``; the confirmed tracks.

        ``view``: the camera's field of view in the same frame as the positions (None: everything is in view).
        Raises TrackingError, changing nothing, when the timestamp is not after the last one, a position or a
        facing is not finite, two people share an id, or ``view`` is not a view. Warns (TimeGapWarning) when the
        frame comes more than ``timeout`` after the last one while there were tracks.
        """
        positions, facing, quality, ids = _measurements(people)
        check_time_order("tracker: frame", timestamp, self._time)
        if view is not None and not isinstance(view, View):
            raise TrackingError(f"tracker: view must be a ViewCone, a ViewRegion or None, got {type(view).__name__}")
        p = self.params
        r, q = p.measurement_sigma**2, p.acceleration_sigma**2
        dt = 0.0 if self._time is None else timestamp - self._time
        self._time = float(timestamp)
        self._note_gap(dt)
        # Tracks undetected for longer than out_of_view_timeout expire below whatever their prediction says: dropped
        # first, so that the prediction never spans more than that (a gap of 1e308 s would overflow it).
        self._keep(timestamp - self._last_hit <= p.out_of_view_timeout + TIME_TOLERANCE)
        # A standing track out of the camera's view holds its place: its velocity is noise about zero, and a group
        # that left the view drifted 0.5 m in the 4 s its tracks coast (a probe's drive_past_group). In view, a miss
        # is the detector's, and the track coasts on as before.
        self._motion.predict(dt, q, hold=~self._walking & (self._detection < 0) & ~self._in_view)
        self._in_view = np.ones(len(self._ids), dtype=bool) if view is None else view.contains(self._motion.position)
        self._unseen += np.where(self._in_view & ~_behind(view, self._motion.position, positions), dt, 0.0)
        rows, cols = self._assign(positions, facing, r, dt)
        self._motion.correct(rows, positions[cols], r)
        self._smooth_facing(rows, facing[cols], quality[cols], timestamp)
        self._hits[rows] += 1
        self._last_hit[rows] = timestamp
        self._unseen[rows] = 0.0
        # Two detections confirm when they are confirm_time apart: the last one's time, not this frame's (a track
        # missed now, 0.2 s after its first hit at 10 Hz, was confirmed by the miss that should end it).
        self._confirmed |= (self._hits >= p.confirm_hits) | (
            (self._hits >= 2) & (self._last_hit - self._first_hit >= p.confirm_time - TIME_TOLERANCE)
        )
        self._detection[:] = -1
        self._detection[rows] = cols
        # A tentative track dies at its first miss; a confirmed one when missed after the timeout (expired only now, so
        # that a detection coming after a long gap, a slow detector's next frame, can still continue it).
        self._keep((self._confirmed | (self._detection >= 0)) & ~self._expired())
        if len(cols) < len(ids):
            unmatched = np.ones(len(ids), dtype=bool)
            unmatched[cols] = False
            self._start(np.flatnonzero(unmatched), positions, facing, quality, timestamp)
        velocity, speed_sigma = self._motion.velocity, np.sqrt(self._motion.covariance[:, 2])
        speed = np.sqrt(velocity[:, 0] ** 2 + velocity[:, 1] ** 2)
        # a young track's velocity is mostly noise: it must exceed walk_speed by its own standard deviation
        self._walking = np.where(self._walking, speed > p.stand_speed, speed - speed_sigma > p.walk_speed)
        return self._report(ids)

    def _note_gap(self, dt: float) -> None:
        """TimeGapWarning when ``dt`` (s since the last frame) exceeds the timeout while there were tracks (tentative
        ones too: at timestamps in nanoseconds none is ever confirmed), once for such frames in a row."""
        timeout = self.params.timeout
        gap = dt > timeout + TIME_TOLERANCE
        if gap and not self._gap_in_a_row and len(self._ids):
            warnings.warn(
                TimeGapWarning(
                    f"{dt:.3g} s after the last frame, more than the tracker's timeout ({timeout:g} s): every track in "
                    "view that it missed ended (are the timestamps in seconds?); the frames right after it that do the "
                    "same are not noted"
                ),
                stacklevel=3,
            )
        self._gap_in_a_row = gap

    def _expired(self) -> np.ndarray:
        """(N,) bool: the tracks undetected (this frame included) for longer than ``timeout`` while the camera could
        see them. Time hidden (out of view, behind someone) does not count towards it: a walker hidden behind a group
        for longer than it, then in view a moment before being detected again, keeps the track."""
        return self._unseen > self.params.timeout + TIME_TOLERANCE

    def _assign(self, positions: np.ndarray, facing: np.ndarray, r: float, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Rows of tracks and columns of detections matched by minimum total distance, each within its gate.

        A walking track faster than ``walk_speed`` that was missed in the last frame also refuses a detection facing
        more than ``heading_gate`` away from its heading: walkers face where they go, and this keeps a track that
        coasts out of view from taking over someone walking the other way into view where it left."""
        if not len(self._ids) or not len(positions):
            return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)
        p = self.params
        # At a slow rate a walker moves farther than max_gate between frames (1.3 m at 1 Hz): a new track, whose
        # velocity is still 0, never caught them again, and no walker was ever reported. Once a track has a velocity
        # its prediction follows the walker, and max_gate holds.
        bound = np.where(self._hits == 1, max(p.max_gate, p.max_speed * dt), p.max_gate)
        gate = np.clip(p.gate_sigmas * np.sqrt(self._motion.innovation_variance(r)), p.min_gate, bound)
        d = self._motion.position[:, None, :] - positions[None, :, :]
        distance = np.sqrt(d[..., 0] ** 2 + d[..., 1] ** 2)
        allowed = distance <= gate[:, None]
        velocity = self._motion.velocity
        speed = np.sqrt(velocity[:, 0] ** 2 + velocity[:, 1] ** 2)
        # coasting (missed in the last frame) walkers: one seen all along who turns round is still that person. A
        # detection is refused when it faces away from both the track's velocity and its own facing (where it has
        # one): a person stepping backwards faces against their velocity (the velocity alone refused them at every
        # miss: 18 tracks in 20 s), and a detector's front/back flip turns the facing, not the velocity.
        striding = self._walking & (speed > p.walk_speed) & (self._detection < 0)
        if striding.any():
            heading = velocity[striding] / speed[striding, None]
            own = self._facing[striding]
            norm = np.sqrt(own[:, 0] ** 2 + own[:, 1] ** 2)  # NaN: no facing yet
            limit = math.cos(p.heading_gate)
            away = heading @ facing.T < limit  # NaN facing: False, allowed
            away &= ~((own / norm[:, None]) @ facing.T >= limit)  # an unknown own facing refuses by the velocity
            turned = away
            allowed[striding] &= ~turned
        return gated_assignment(distance, allowed)

    def _smooth_facing(self, rows: np.ndarray, measured: np.ndarray, quality: np.ndarray, timestamp: float) -> None:
        """Average facings (K, 2) unit vectors (NaN: none) measured at ``timestamp`` (s) into the tracks ``rows``
        (exponentially, time constant ``facing_tau``: each weighted by the time since its track's last measured
        facing; the average's direction is the track's facing); their orientation qualities (K,) (NaN: none)
        likewise."""
        tau = self.params.facing_tau
        old, old_quality = self._facing[rows], self._quality[rows]
        weight = 1.0 - np.exp(-(timestamp - self._facing_time[rows]) / tau) if tau > 0 else np.ones(len(rows))
        mixed = (1 - weight[:, None]) * old + weight[:, None] * measured
        mixed = np.where(np.isnan(old), measured, np.where(np.isnan(measured), old, mixed))
        mixed_quality = (1 - weight) * old_quality + weight * quality
        mixed_quality = np.where(
            np.isnan(old_quality), quality, np.where(np.isnan(quality), old_quality, mixed_quality)
        )
        norm = np.sqrt(mixed[:, 0] ** 2 + mixed[:, 1] ** 2)
        flat = ~(norm > 1e-9)  # exactly opposite facings average to nothing: take the new one
        mixed[flat], mixed_quality[flat] = measured[flat], quality[flat]
        # Not renormalised: renormalised each frame, a facing turned exactly round (a detector's front/back flip)
        # left (1 - 2w) times the old one, which kept the old direction for ever (7.8 s at 10 Hz with a little
        # noise); the average itself shrinks and turns over within tau ln 2 whatever the rate.
        self._facing[rows] = mixed
        self._quality[rows] = mixed_quality
        self._facing_time[rows[~np.isnan(measured[:, 0])]] = timestamp

    def _start(
        self, cols: np.ndarray, positions: np.ndarray, facing: np.ndarray, quality: np.ndarray, timestamp: float
    ) -> None:
        """Tentative tracks for the detections ``cols``."""
        k = len(cols)
        p = self.params
        self._motion.append(positions[cols], p.measurement_sigma**2, p.initial_speed_sigma**2)
        self._ids = np.concatenate((self._ids, np.arange(self._next_id, self._next_id + k)))
        self._next_id += k
        self._hits = np.concatenate((self._hits, np.ones(k, dtype=np.int64)))
        self._confirmed = np.concatenate((self._confirmed, np.full(k, p.confirm_hits <= 1)))
        self._walking = np.concatenate((self._walking, np.zeros(k, dtype=bool)))
        self._last_hit = np.concatenate((self._last_hit, np.full(k, timestamp)))
        self._unseen = np.concatenate((self._unseen, np.zeros(k)))
        self._first_hit = np.concatenate((self._first_hit, np.full(k, timestamp)))
        self._detection = np.concatenate((self._detection, cols))
        self._in_view = np.concatenate((self._in_view, np.ones(k, dtype=bool)))  # just detected
        self._facing = np.concatenate((self._facing, facing[cols]))
        self._quality = np.concatenate((self._quality, quality[cols]))
        self._facing_time = np.concatenate((self._facing_time, np.where(np.isnan(facing[cols, 0]), np.nan, timestamp)))

    def _keep(self, mask: np.ndarray) -> None:
        if mask.all():
            return
        self._motion.keep(mask)
        self._ids, self._hits, self._confirmed = self._ids[mask], self._hits[mask], self._confirmed[mask]
        self._walking, self._last_hit, self._first_hit = (
            self._walking[mask],
            self._last_hit[mask],
            self._first_hit[mask],
        )
        self._unseen = self._unseen[mask]
        self._detection, self._facing, self._in_view = self._detection[mask], self._facing[mask], self._in_view[mask]
        self._facing_time, self._quality = self._facing_time[mask], self._quality[mask]

    def _report(self, ids: list[int]) -> list[TrackedPerson]:
        rows = np.flatnonzero(self._confirmed)
        in_view = self._in_view[rows].tolist()
        speed_sigma = np.sqrt(self._motion.covariance[rows, 2]).tolist()
        facing = self._facing[rows]
        theta = [None if t != t else t for t in np.arctan2(facing[:, 1], facing[:, 0]).tolist()]  # NaN -> None
        quality = np.nan_to_num(self._quality[rows], nan=0.0).tolist()  # no facing: quality 0
        detection = self._detection[rows].tolist()
        missed = self._unseen[rows].tolist()
        return [
            TrackedPerson(
                track_id,
                x,
                y,
                vx,
                vy,
                th,
                "walking" if walking else "standing",
                d >= 0,
                seen,
                last,
                ids[d] if d >= 0 else None,
                sd,
                q,
                unseen,
            )
            for track_id, (x, y), (vx, vy), th, walking, d, seen, last, sd, q, unseen in zip(
                self._ids[rows].tolist(),
                self._motion.position[rows].tolist(),
                self._motion.velocity[rows].tolist(),
                theta,
                self._walking[rows].tolist(),
                detection,
                in_view,
                self._last_hit[rows].tolist(),
                speed_sigma,
                quality,
                missed,
                strict=True,
            )
        ]


def _behind(view: View | None, positions: np.ndarray, detections: np.ndarray) -> np.ndarray:
    """(N,) bool: which of the (N, 2) track ``positions`` a camera's cone sees behind one of this frame's (M, 2)
    ``detections``. A person walking behind a group is hidden for longer than ``timeout`` and must keep their track:
    with the in-view timeout it was deleted while hidden, and the person came out under a new id. Without a camera
    (no view, or a region seen from above) nobody hides anybody."""
    if not isinstance(view, ViewCone):
        return np.zeros(len(positions), dtype=bool)
    return view.behind(positions, detections, OCCLUDER_RADIUS)


def check_people(people: Sequence[Person]) -> None:
    """Raise TrackingError, as ``PeopleTracker.update`` would, when ``people`` hold an id that is not a whole number
    or given twice, or a position, facing or orientation quality that is not a finite number in range."""
    _measurements(people)


def _measurements(people: Sequence[Person]) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[int]]:
    """Positions (N, 2) m, facings (N, 2) unit vectors and their orientation qualities (N,) in [0, 1] (both NaN:
    unknown) and ids of ``people``; TrackingError on bad values."""
    for person in people:  # before numpy, which would read "1.5" as a number
        if isinstance(person.id, bool) or not isinstance(person.id, numbers.Integral):
            raise TrackingError(f"tracker: person id {person.id!r} is not a whole number")
        for name in ("x", "y") if person.theta is None else ("x", "y", "theta", "orientation_quality"):
            if not is_real(getattr(person, name)):
                raise TrackingError(f"tracker: person {person.id}: {name} is not a number: {getattr(person, name)!r}")
    ids = [int(p.id) for p in people]
    positions = np.array([(p.x, p.y) for p in people], dtype=float).reshape(-1, 2)
    theta = np.array([np.nan if p.theta is None else p.theta for p in people], dtype=float)
    quality = np.array([np.nan if p.theta is None else p.orientation_quality for p in people], dtype=float)
    known = [p.theta is not None for p in people]
    good_quality = (quality[known] >= 0) & (quality[known] <= 1)  # NaN: False
    facings_ok = (np.abs(theta[known]) <= YAW_LIMIT_RAD).all()  # NaN: False
    if not (np.isfinite(positions).all() and facings_ok and good_quality.all()) or (
        len(positions) and np.abs(positions).max() > MAX_COORDINATE
    ):
        for person in people:  # name the first bad one
            owner = f"tracker: person {person.id}"
            check_numbers(
                owner, person, ("x", "y"), low=-MAX_COORDINATE, high=MAX_COORDINATE, unit="metres", error=TrackingError
            )
            if person.theta is not None:
                check_yaws(owner, person, ("theta",), error=TrackingError)
                check_numbers(owner, person, ("orientation_quality",), low=0, high=1, error=TrackingError)
    if len(set(ids)) != len(ids):
        twice = sorted({i for i in ids if ids.count(i) > 1})
        raise TrackingError(f"tracker: person id {twice[0]} appears twice in one frame")
    return positions, np.column_stack((np.cos(theta), np.sin(theta))), quality, ids
