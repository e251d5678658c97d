"""Groups over time: stable group ids, hysteresis, members who walk away, and people walking together.

Per frame (``GroupTracker.update``), on the tracked people (``sid.tracking.tracker``):

- conversations: ``sid.perception.groups.detect_groups`` on the standing tracks (smoothed positions and facings).
  Walking tracks are left out, so people walking together are never an o-space, whatever their facings.
- walking groups: moving tracks (walking, or faster than ``moving_speed``: the tracker calls a young track walking
  only once its speed is known, a second or more after it appeared) within ``walk_distance`` of each other whose
  velocities differ by at most ``walk_velocity_difference`` (side by side or in file), joined transitively
  (connected components).
- each candidate is matched to a group track of its kind by member overlap (Jaccard index): as many pairs with an
  overlap of ``min_overlap`` or more as can be matched, of the greatest total overlap among those matchings
  (``sid.tracking.assignment.gated_assignment``); an unmatched candidate starts a tentative group.
- a conversation is reported once it was found in ``confirm_hits`` of its last ``confirm_window`` frames, a walking
  group in ``walk_confirm_hits`` of them (1: when first found; its rule already looks back ``walk_window``); it survives
  frames in which it is not found for up to ``miss_timeout`` seconds, keeping its last geometry, but a member who
  leaves (track deleted, starts walking for a conversation or stops for a walking group, or goes farther than
  ``leave_distance`` from the interest point, or is found in another group) leaves the group at once, and one
  not found with the group for ``miss_timeout`` leaves too; fewer than two members end it.
- only standing tracks that are not moving and whose velocity is settled (``max_speed_sigma``) take part in
  conversations.

Group ids count up from 1 and are never reused, also across ``reset``.
"""

from __future__ import annotations

import itertools
import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from sid.checks import check_number, check_numbers, check_whole
from sid.errors import InputError
from sid.perception.groups import GroupParams, detect_groups
from sid.tracking.assignment import gated_assignment
from sid.tracking.records import TIME_TOLERANCE, GroupKind, TrackedGroup, TrackedPerson
from sid.tracking.tracker import check_time_order

__all__ = ["GroupTracker", "GroupTrackerParams", "connected_components", "pair_distance"]

_NO_ZONE = np.zeros((0, 2))
_CLOSENESS_STEP = 0.2
"""Seconds between the past frames in which walkers' closeness is checked (``GroupTrackerParams.walk_window``): a
15 Hz camera's frames thinned to about what the real crowds were annotated at (0.4 s), where the rule was chosen;
nobody walks in and out of a walking group's reach between two looks."""


@dataclass(frozen=True)
class GroupTrackerParams:
    """Parameters of ``GroupTracker`` (metres, seconds, m/s; measured in docs/tracking.md).

    confirm_hits of confirm_window: a conversation is reported after being found in that many of its last frames,
    or in two frames in a row at least confirm_time apart (s; a slow detector, as ``TrackerParams.confirm_time``).
    walk_confirm_hits: the same for a walking group (1: reported when first found, as its rule already asks the
    walkers to have stayed close over walk_window).
    miss_timeout: seconds a reported group survives while not found. min_overlap: the Jaccard index of member sets
    above which a candidate continues a group. leave_distance: a member of a conversation farther than this from
    its interest point (m) has left. walk_distance (m), walk_velocity_difference (m/s): walkers who stayed closer
    than this to each other over the last walk_window seconds (s) and moved apart slower than that walk together.
    max_speed_sigma: a standing track joins conversations
    only once its velocity is known within this (m/s, ``TrackedPerson.speed_sigma``): a track just started may be a
    walker whose motion is not yet seen. moving_speed: a track faster than this (m/s) takes part in walking groups
    whatever its walking / standing state.
    """

    confirm_hits: int = 3
    walk_confirm_hits: int = 1
    confirm_window: int = 5
    confirm_time: float = 0.2
    miss_timeout: float = 1.0
    min_overlap: float = 0.5
    leave_distance: float = 1.6
    walk_distance: float = 1.5
    walk_velocity_difference: float = 1.0
    walk_window: float = 4.0
    max_speed_sigma: float = 0.4
    moving_speed: float = 0.4

    def __post_init__(self) -> None:
        for name in ("confirm_hits", "walk_confirm_hits", "confirm_window"):
            check_whole("group tracker", name, getattr(self, name), low=1)
        for name in ("confirm_hits", "walk_confirm_hits"):
            if getattr(self, name) > self.confirm_window:
                raise InputError(
                    f"group tracker: {name} ({getattr(self, name)}) must not exceed confirm_window "
                    f"({self.confirm_window})"
                )
        check_number("group tracker", "miss_timeout", self.miss_timeout, low=0, unit="seconds")
        check_number("group tracker", "confirm_time", self.confirm_time, low=0, unit="seconds")
        check_number("group tracker", "min_overlap", self.min_overlap, low=0, high=1, low_open=True)
        check_numbers("group tracker", self, ("leave_distance", "walk_distance"), low=0, low_open=True, unit="metres")
        speeds = ("walk_velocity_difference", "max_speed_sigma", "moving_speed")
        check_numbers("group tracker", self, speeds, low=0, unit="m/s")
        check_number("group tracker", "walk_window", self.walk_window, low=0, high=60, unit="seconds")


@dataclass(frozen=True)
class _Positions:
    """The tracks at one past frame: timestamp (s), sorted track ids, (K, 2) positions (m)."""

    timestamp: float
    ids: np.ndarray
    positions: np.ndarray


@dataclass
class _Candidate:
    """A group found in this frame: kind, members (track ids) and geometry."""

    kind: GroupKind
    members: frozenset[int]
    interest_point: tuple[float, float]
    zone: np.ndarray
    area: float
    spread: float


@dataclass
class _GroupTrack:
    """A group over time: its last candidate, its members (track id -> when last found in the group, s)."""

    id: int
    found: _Candidate
    members: dict[int, float]
    last_seen: float
    history: deque[bool] = field(default_factory=deque)
    confirmed: bool = False


class GroupTracker:
    """Keeps groups of tracked people across frames. State lives between calls."""

    def __init__(self, params: GroupTrackerParams | None = None, group_params: GroupParams | None = None) -> None:
        self.params = params or GroupTrackerParams()
        self.group_params = group_params or GroupParams()
        self._next_id = 1
        self._tracks: list[_GroupTrack] = []
        self._history: deque[_Positions] = deque()
        self._last_time: float | None = None  # of the last update

    def reset(self) -> None:
        """Forget every group (ids keep counting up)."""
        self._tracks = []
        self._history = deque()
        self._last_time = None

    def update(self, people: Sequence[TrackedPerson], timestamp: float) -> list[TrackedGroup]:
        """The confirmed groups among ``people`` (this frame's tracks) at ``timestamp`` (s); TrackingError, changing
        nothing, when the timestamp is not after the last one."""
        check_time_order("group tracker: frame", timestamp, self._last_time)
        by_id = {p.id: p for p in people}
        if len(by_id) != len(people):
            raise InputError("group tracker: a track id appears twice in one frame")
        self._remember(people, timestamp)
        candidates = self._conversations(people) + _walking_groups(people, self._history, self.params)
        matched = self._match(candidates)
        found_now = {m for candidate in candidates for m in candidate.members}
        p = self.params
        kept: list[_GroupTrack] = []
        slow = self._last_time is not None and timestamp - self._last_time >= p.confirm_time - TIME_TOLERANCE
        self._last_time = timestamp
        for track in self._tracks:
            candidate = matched.get(track.id)
            track.history.append(candidate is not None)
            while len(track.history) > p.confirm_window:
                track.history.popleft()
            found = frozenset() if candidate is None else candidate.members
            if candidate is not None:
                track.found, track.last_seen = candidate, timestamp
                track.members |= dict.fromkeys(found, timestamp)
            elif timestamp - track.last_seen > p.miss_timeout + TIME_TOLERANCE:
                continue
            track.members = {
                m: seen
                for m, seen in track.members.items()
                if m in found
                or (
                    m not in found_now  # found in another group now: moved there
                    and timestamp - seen <= p.miss_timeout + TIME_TOLERANCE
                    and self._stays(track, by_id.get(m))
                )
            }
            hits = p.walk_confirm_hits if track.found.kind == "walking" else p.confirm_hits
            twice = slow and len(track.history) >= 2 and track.history[-1] and track.history[-2]
            track.confirmed |= sum(track.history) >= hits or twice
            if len(track.members) >= 2:
                kept.append(track)
        self._tracks = kept
        return [_report(track, by_id) for track in self._tracks if track.confirmed]

    def _remember(self, people: Sequence[TrackedPerson], timestamp: float) -> None:
        """Keep the tracks' positions of the last ``walk_window`` seconds (this frame's included)."""
        order = sorted(range(len(people)), key=lambda k: people[k].id)
        ids = np.array([people[k].id for k in order], dtype=np.int64)
        positions = np.array([[people[k].x, people[k].y] for k in order]).reshape(-1, 2)
        self._history.append(_Positions(timestamp, ids, positions))
        while timestamp - self._history[0].timestamp > self.params.walk_window + TIME_TOLERANCE:
            self._history.popleft()

    def _conversations(self, people: Sequence[TrackedPerson]) -> list[_Candidate]:
        settled = self.params.max_speed_sigma
        standing = [p.as_person() for p in people if not _moving(p, self.params) and p.speed_sigma <= settled]
        return [
            _Candidate(
                "conversation",
                frozenset(g.members),
                (float(g.interest_point[0]), float(g.interest_point[1])),
                np.asarray(g.zone, dtype=float).reshape(-1, 2),
                float(g.area),
                float(g.spread),
            )
            for g in detect_groups(standing, self.group_params)
        ]

    def _match(self, candidates: list[_Candidate]) -> dict[int, _Candidate]:
        """Group track id -> the candidate continuing it; new tentative tracks for the others."""
        matched: dict[int, _Candidate] = {}
        used: set[int] = set()
        if self._tracks and candidates:
            overlap = np.zeros((len(self._tracks), len(candidates)))  # 0 unless they share a member
            holding: dict[int, list[int]] = {}  # track id -> the candidates holding it
            for col, candidate in enumerate(candidates):
                for member in candidate.members:
                    holding.setdefault(member, []).append(col)
            for row, track in enumerate(self._tracks):
                for col in {c for member in track.members for c in holding.get(member, ())}:
                    overlap[row, col] = _jaccard(track, candidates[col])
            rows, cols = gated_assignment(-overlap, overlap >= self.params.min_overlap)
            for row, col in zip(rows.tolist(), cols.tolist(), strict=True):
                matched[self._tracks[row].id] = candidates[col]
                used.add(col)
        for col, candidate in enumerate(candidates):
            if col not in used:
                track = _GroupTrack(self._next_id, candidate, {}, -np.inf)
                self._next_id += 1
                self._tracks.append(track)
                matched[track.id] = candidate
        return matched

    def _stays(self, track: _GroupTrack, person: TrackedPerson | None) -> bool:
        """Whether a member of a group not found this frame is still in it."""
        if person is None:
            return False
        if track.found.kind == "walking":
            return _moving(person, self.params)
        x, y = track.found.interest_point
        return not person.walking and np.hypot(person.x - x, person.y - y) <= self.params.leave_distance


def _jaccard(track: _GroupTrack, candidate: _Candidate) -> float:
    if track.found.kind != candidate.kind:
        return 0.0
    members = track.members.keys()
    return len(members & candidate.members) / len(members | candidate.members)


def _walking_groups(
    people: Sequence[TrackedPerson], history: deque[_Positions], params: GroupTrackerParams
) -> list[_Candidate]:
    walkers = [p for p in people if _moving(p, params)]
    if len(walkers) < 2:
        return []
    ids = np.array([p.id for p in walkers], dtype=np.int64)
    position = np.array([[p.x, p.y] for p in walkers])
    i, j = np.nonzero(np.triu(pair_distance(position) <= params.walk_distance, 1))
    velocity = np.array([[p.vx, p.vy] for p in walkers])
    alike = _relative_speed(ids, position, velocity, history, params, i, j) <= params.walk_velocity_difference
    i, j = i[alike], j[alike]
    close = _stayed_close(ids, history, params.walk_distance, i, j)
    linked = np.zeros((len(walkers), len(walkers)), dtype=bool)
    linked[i[close], j[close]] = True
    linked |= linked.T
    out = []
    for rows in connected_components(linked):
        if len(rows) < 2:
            continue
        centre = position[rows].mean(axis=0)
        spread = float(np.linalg.norm(position[rows] - centre, axis=1).mean())
        members = frozenset(walkers[i].id for i in rows.tolist())
        out.append(_Candidate("walking", members, (float(centre[0]), float(centre[1])), _NO_ZONE, 0.0, spread))
    return out


def _moving(person: TrackedPerson, params: GroupTrackerParams) -> bool:
    return person.walking or person.vx * person.vx + person.vy * person.vy > params.moving_speed**2


def _relative_speed(
    ids: np.ndarray,
    position: np.ndarray,
    velocity: np.ndarray,
    history: deque[_Positions],
    params: GroupTrackerParams,
    i: np.ndarray,
    j: np.ndarray,
) -> np.ndarray:
    """(P,) speed (m/s) at which each pair (i[k], j[k]) of tracks moves apart: their relative displacement since the
    oldest frame of the last ``walk_window`` seconds in which both were tracked, over that time; for a pair with less
    than half the window in common, the difference of their filtered velocities (noisier). Only the pairs asked for
    (those near each other), and no older frame once every pair has its answer."""
    dv = velocity[i] - velocity[j]
    speed = np.sqrt(dv[:, 0] ** 2 + dv[:, 1] ** 2)
    now = history[-1].timestamp if history else None
    filled = np.zeros(len(i), dtype=bool)
    for old in history:
        span = 0.0 if now is None else now - old.timestamp
        # span 0: the current frame (a window under TIME_TOLERANCE reaches it), which gives no displacement rate.
        if span <= 0 or span < params.walk_window / 2 - TIME_TOLERANCE or filled.all():
            break
        if not len(old.ids):
            continue
        rows = np.minimum(np.searchsorted(old.ids, ids), len(old.ids) - 1)
        present = old.ids[rows] == ids
        both = present[i] & present[j] & ~filled
        if not both.any():
            continue
        then = old.positions[rows]
        moved = (position[i] - position[j]) - (then[i] - then[j])
        relative = np.sqrt(moved[:, 0] ** 2 + moved[:, 1] ** 2) / span
        speed = np.where(both, relative, speed)
        filled |= both
    return speed


def _stayed_close(
    ids: np.ndarray, history: deque[_Positions], distance: float, i: np.ndarray, j: np.ndarray
) -> np.ndarray:
    """(P,) bool: each pair (i[k], j[k]) of tracks ``ids``, within ``distance`` (m) of each other now, was so in every
    frame of ``history`` (the last ``walk_window`` seconds) in which both were tracked, frames looked at at least
    ``_CLOSENESS_STEP`` apart. Strangers who close in on each other for a moment are not yet a group; people walking
    together stay close."""
    close = np.ones(len(i), dtype=bool)
    if not len(i):
        return close
    involved, pairs = np.unique(np.concatenate((i, j)), return_inverse=True)  # the tracks in pairs, and where
    own, a, b = ids[involved], pairs[: len(i)], pairs[len(i) :]
    last = -math.inf
    for old in itertools.islice(history, len(history) - 1):  # this frame's closeness is given
        if old.timestamp < last + _CLOSENESS_STEP - TIME_TOLERANCE or not len(old.ids):
            continue
        last = old.timestamp
        rows = np.minimum(np.searchsorted(old.ids, own), len(old.ids) - 1)
        present = old.ids[rows] == own
        apart = old.positions[rows[a]] - old.positions[rows[b]]
        close &= ~(present[a] & present[b]) | (apart[:, 0] ** 2 + apart[:, 1] ** 2 <= distance * distance)
        if not close.any():
            break
    return close


def pair_distance(points: np.ndarray) -> np.ndarray:
    """(N, N) distances between the rows of (N, 2) ``points`` (positions, m; or velocities, m/s)."""
    d = points[:, None, :] - points[None, :, :]
    return np.sqrt(d[..., 0] ** 2 + d[..., 1] ** 2)


def connected_components(adjacent: np.ndarray) -> list[np.ndarray]:
    """The connected components of a symmetric (N, N) bool adjacency matrix, as index arrays ordered by their first
    index. Union-find over the links (a few per walker), where ``scipy.sparse.csgraph`` would add its imports to
    every start (docs/benchmarks.md, "Start-up and the detect loop") and squaring the reachability matrix costs
    O(N^3) per product."""
    if not len(adjacent):
        return []
    parent = list(range(len(adjacent)))  # union-find over the links; a component's root is its first index

    def root(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a, b in zip(*np.nonzero(np.triu(adjacent, 1)), strict=True):
        ra, rb = root(int(a)), root(int(b))
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    labels = np.array([root(a) for a in range(len(adjacent))])
    return [np.flatnonzero(labels == label) for label in np.unique(labels)]


def _report(track: _GroupTrack, by_id: dict[int, TrackedPerson]) -> TrackedGroup:
    members = sorted(track.members)
    people = [by_id[m] for m in members]
    velocity = (sum(p.vx for p in people) / len(people), sum(p.vy for p in people) / len(people))
    found = track.found
    interest = found.interest_point
    if found.kind == "walking":  # walkers move on: the centroid of this frame, not of the last time found
        interest = (sum(p.x for p in people) / len(people), sum(p.y for p in people) / len(people))
    return TrackedGroup(
        track.id,
        found.kind,
        tuple(members),
        (float(interest[0]), float(interest[1])),
        found.zone,
        found.area,
        found.spread,
        (float(velocity[0]), float(velocity[1])),
        track.last_seen,
    )
