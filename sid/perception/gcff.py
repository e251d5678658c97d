"""GCFF: F-formations by graph cuts (Setti, Russell, Bassetti and Cristani, PLoS One 2015, "F-formation detection:
individuating free-standing conversational groups in images"), written here from the paper's description and
the behaviour of its published MATLAB code (read to pin down the details; no code taken); world frame, metres,
radians.

The model. Person i at p_i facing yaw theta_i votes for an o-space centre a fixed ``stride`` ahead,
v_i = p_i + stride (cos theta_i, sin theta_i). A labelling assigns each person to one candidate o-space (a label)
with centre c_l, and costs

    E = sum_i |v_i - c_{l_i}|^2 + V_i(c_{l_i})  +  mdl x (number of labels used)              (m^2)

the squared distances being the negative log-likelihood of a Gaussian around the centre, ``mdl`` the description
length of one more o-space (minimum description length); a person alone is a label of their own and pays it too, so
two people share a label only when that saves more than their distances cost. V_i is the visibility term: the
o-space is exclusive, and person k pays, for every person j nearer the centre in nearly the same direction (the
cosine between c->p_j and c->p_k above ``visibility_cosine``, both with a vote cost below mdl),

    visibility_unit x visibility_base ^ (cosine x |p_k - c| / |p_j - c|)                        (m^2)

whoever j is assigned to: a person hidden behind another from the centre has no direct access to it. The defaults
are the published detector's constants, which were in centimetres: base 100 on a unit of 1 cm^2 = 1e-4 m^2 (a
minimum of 100^0.75 cm^2 = 0.003 m^2, 1 m^2 at twice the distance straight behind, 100 m^2 at three times). A pair
term is capped at 1e6 x mdl, far beyond anything worth paying: the cap only keeps the sums finite and precise.

The search. Every person's vote starts as a candidate centre, each person on their own (so a pair forms only when
one's vote is within sqrt(mdl) of the other's, the mean centre being proposed only once they share a label). Then,
up to ``max_rounds``
times: (1) the assignment with the centres fixed, by alpha-expansion moves with label costs (one label alpha
offers itself to everyone; each person may switch to it, and a label whose members all leave stops paying its
cost); (2) each used label's centre becomes the mean of its members' votes, unused labels are dropped, and the
costs are recomputed; until the assignment no longer changes. People in one label form a group.

With no pairwise terms (GCFF has none) an expansion move decomposes over the current labels and is solved exactly
in closed form: the members of label l either all switch to alpha (saving mdl) or each switches when alpha is
cheaper for them, whichever costs less; the move pays alpha's own cost when alpha was unused. So no max-flow is
needed, and no GCO binding: the ``gco`` wheel on PyPI (2.0.2, with label costs) would add a compiled dependency for
what these few lines solve exactly, and GCO sweeps the labels in index order, which makes the answer depend on the
order in which the people are listed.

``order`` chooses how the moves are sequenced:

- ``"best"`` (default): each move is the expansion that lowers the energy most (steepest descent over expansion
  moves), until none lowers it by more than 1e-9 x mdl. It is independent of the order of the people and of rigid
  motions and reflections of the scene; exact ties (symmetric scenes, e.g. a regular polygon of people) go to the
  lowest label, i.e. the person listed first, and the tied moves are images of each other under the symmetry.
- ``"input"``: the published detector's own sequence: labels are expanded cyclically in index order (the people's
  order, then each label's rank among the surviving ones), a move is kept unless it raises the energy (ties kept),
  and a solve ends after as many expansions in a row as there are labels without a decrease. It reproduces the
  published code's groups, and so depends on the input order.

How each order scores against the published figures on the benchmarks: docs/groups.md.

Decided here, where the paper is silent (the benchmark annotations all have facings):
- A person with unknown facing (NaN yaw) casts no vote. Their cost for a centre c is (|p - c| - stride)^2, the
  squared distance from c to the nearest place they could have voted for (as if facing c); they count in the
  visibility term like anyone; they do not move the centres (the mean runs over known votes only), and they start
  on a label of their own that nobody else can join. A label left with no known facing dissolves into such labels,
  so a group always has a known facing.
- Labels: ``gcff_labels`` numbers the groups of two or more people 0, 1, ... in order of each group's lowest member
  index; a person alone gets -1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sid.checks import MAX_LENGTH, check_limit, check_number, check_whole
from sid.errors import InputError, InputTypeError

__all__ = ["GCFF_ORDERS", "GCFFParams", "gcff_labels"]

GCFF_ORDERS = ("best", "input")
"""The move orders of ``GCFFParams.order`` (module docstring)."""

# A pair's visibility penalty is capped at this many label costs (m^2): it is then never worth paying, and the sums of
# many such terms stay finite and precise to ~1e-10 mdl.
_PENALTY_CAP = 1e6
# Relative (to mdl) energy change below which "best" treats two moves as tied, and a move as no improvement; rounding
# after a rigid motion changes energies by ~1e-15 mdl.
_TIE = 1e-9
# Distance (m) from a centre within which a person stands on it, as far as rounding can tell: coordinates of 1 km carry
# errors of ~1e-13 m.
_ON_CENTRE_M = 1e-9
# Stand-in for a forbidden assignment (joining an unknown facing's own label) in sums: 0 x inf would make them NaN.
_FORBIDDEN = 1e200


@dataclass(frozen=True)
class GCFFParams:
    """Constants of the GCFF detector (metres, square metres; module docstring for the model).

    stride: distance (m) ahead of a person, along their facing, at which they vote for the o-space centre.
      0.45: a conversational circle of about 1 m across (the published detector's common setting, 45 cm).
    mdl: cost (m^2) of one o-space, and of each person alone: people share one when the squared distances of
      their votes from its centre sum to less than the labels they save. 3.0 (30000 cm^2, the common setting).
    visibility_cosine: a person nearer the centre blocks another when the cosine of the angle between them, seen
      from the centre, exceeds this. 0.75 (~41 degrees), the published value.
    visibility_base, visibility_unit: the penalty for each blocker is unit x base ^ (cosine x distance ratio)
      (m^2). 100 and 1e-4 m^2 (1 cm^2): the published detector's constants, which worked in centimetres.
      ``visibility_unit=0`` turns the visibility term off.
    max_rounds: most assignment-and-refit rounds. 10, as published; a frame that alternates between two
      assignments stops there.
    order: ``"best"`` (steepest descent over expansion moves, independent of the input order) or ``"input"``
      (the published detector's cyclic sweep in label order, which depends on it; module docstring).

    Settings of the benchmarks' ``settings_gc.mat`` files: ``sid.experiments.fformation.load_settings_gc``.
    """

    stride: float = 0.45
    mdl: float = 3.0
    visibility_cosine: float = 0.75
    visibility_base: float = 100.0
    visibility_unit: float = 1e-4
    max_rounds: int = 10
    order: str = "best"

    def __post_init__(self) -> None:
        # Bounded as the o-space lengths are: squared and summed downstream, 1e308 overflowed to garbage groups.
        check_number("gcff", "stride", self.stride, low=0, high=MAX_LENGTH, unit="metres")
        check_number("gcff", "mdl", self.mdl, low=0, low_open=True, high=MAX_LENGTH**2, unit="square metres")
        check_number("gcff", "visibility_cosine", self.visibility_cosine, low=-1, high=1)
        check_number("gcff", "visibility_base", self.visibility_base, low=1)
        check_number("gcff", "visibility_unit", self.visibility_unit, low=0, unit="square metres")
        check_whole("gcff", "max_rounds", self.max_rounds, low=1)
        if self.order not in GCFF_ORDERS:
            raise InputError(f"gcff: order must be one of {', '.join(GCFF_ORDERS)}, got {self.order!r}")


def gcff_labels(positions: np.ndarray, yaw: np.ndarray, params: GCFFParams | None = None) -> np.ndarray:
    """A group label per person: (N,) ints, 0, 1, ... for groups of two or more people, numbered in order of each
    group's lowest member index, and -1 for a person alone.

    positions: (N, 2) x, y in the world frame (m). yaw: (N,) facing angles (rad, facing (cos, sin)); NaN is an
    unknown facing (module docstring). params: the model's constants (default ``GCFFParams()``).

    Raises ValueError naming the problem for a non-finite position, an infinite yaw, or arrays of the wrong shape;
    ``sid.checks.LimitError`` (a ValueError) above the ``people`` limit.
    """
    params = params if params is not None else GCFFParams()
    if not isinstance(params, GCFFParams):
        raise InputTypeError(f"gcff: params must be GCFFParams, got {type(params).__name__}")
    xy, theta = _checked(positions, yaw)
    count = len(xy)
    if count == 0:
        return np.zeros(0, dtype=int)
    known = ~np.isnan(theta)
    votes = xy + params.stride * np.column_stack((np.cos(theta), np.sin(theta)))
    votes[~known] = np.nan
    # Candidate labels: a centre each (NaN for an unknown facing's own label) and its owner (-1, or that person).
    owners = np.where(known, -1, np.arange(count))
    centres = votes.copy()
    labels = np.arange(count)
    cost = _costs(xy, votes, known, centres, owners, params)
    solve = _best_moves if params.order == "best" else _input_moves
    for _ in range(params.max_rounds):
        assigned = solve(cost, labels, params.mdl)
        assigned, centres, owners = _refit(assigned, votes, known, owners)
        if np.array_equal(assigned, labels):
            break
        labels = assigned
        cost = _costs(xy, votes, known, centres, owners, params)
    return _canonical(assigned)


def _checked(positions: np.ndarray, yaw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Positions as an (N, 2) float array and yaws as (N,), or ValueError naming what is wrong."""
    try:
        xy = np.asarray(positions, dtype=float)
        theta = np.asarray(yaw, dtype=float)
    except (TypeError, ValueError):
        raise InputError("gcff: positions and yaw must be numeric arrays") from None
    if xy.size == 0 and theta.size == 0:
        return np.zeros((0, 2)), np.zeros(0)
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise InputError(f"gcff: positions must be an (N, 2) array of x, y (m), got shape {xy.shape}")
    if theta.ndim != 1 or len(theta) != len(xy):
        raise InputError(f"gcff: yaw must be an ({len(xy)},) array, one angle per position, got shape {theta.shape}")
    check_limit("gcff: positions", len(xy), "people", "people")
    bad = np.flatnonzero(~np.isfinite(xy).all(axis=1))
    if len(bad):
        raise InputError(f"gcff: positions must be finite, row {bad[0]} is {xy[bad[0]].tolist()}")
    bad = np.flatnonzero(np.isinf(theta))
    if len(bad):
        raise InputError(f"gcff: yaw must be finite or NaN (unknown facing), yaw[{bad[0]}] is {theta[bad[0]]}")
    return xy, theta


def _costs(
    xy: np.ndarray, votes: np.ndarray, known: np.ndarray, centres: np.ndarray, owners: np.ndarray, params: GCFFParams
) -> np.ndarray:
    """(N, K) cost (m^2) of each person joining each label: the squared distance of their vote from its centre
    (unknown facing: of the nearest vote they could cast) plus the visibility penalty; an unknown facing's own label
    costs its owner 0 and is forbidden (inf) to everyone else."""
    count = len(xy)
    cost = np.empty((count, len(owners)))
    mdl, unit = params.mdl, params.visibility_unit
    cap = _PENALTY_CAP * mdl
    for k, (centre, owner) in enumerate(zip(centres, owners, strict=True)):
        if owner >= 0:
            cost[:, k] = np.inf
            cost[owner, k] = 0.0
            continue
        offset = xy - centre  # from the centre to each person
        distance = np.hypot(offset[:, 0], offset[:, 1])
        column = np.where(known, ((votes - centre) ** 2).sum(axis=1), (distance - params.stride) ** 2)
        near = np.flatnonzero(column < mdl)
        if unit > 0 and len(near) > 1:
            # Rows: the person blocked (farther from the centre); columns: the person in front.
            o, d = offset[near], distance[near]
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                # (Products written out: BLAS on an (m, 2) x (2, m) product is slower than this.)
                inner = o[:, 0, None] * o[None, :, 0] + o[:, 1, None] * o[None, :, 1]
                cosine = inner / (d[:, None] * d[None, :])
                # Someone on the centre (within rounding of it: a turned or moved scene puts them 1e-16 m off in any
                # direction) has no direction from it: they block nobody and nobody blocks them.
                off_centre = d > _ON_CENTRE_M
                blocks = (d[:, None] > d[None, :]) & (cosine > params.visibility_cosine)
                blocks &= off_centre[:, None] & off_centre[None, :]
                penalty = np.minimum(unit * params.visibility_base ** (cosine * d[:, None] / d[None, :]), cap)
            column[near] += np.where(blocks, penalty, 0.0).sum(axis=1)
        cost[:, k] = column
    return cost


def _expansions(
    cost: np.ndarray, labels: np.ndarray, alphas: np.ndarray, mdl: float, tie: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The optimal expansion move on each label of ``alphas`` from ``labels``: its energy change (A,) (m^2), and who
    moves: (K, A) whether label l's members all switch to alpha, (N, A) whether person i switches by themself.

    Per current label l != alpha: either every member switches (the label's cost is saved) or each member whose cost
    falls by more than ``tie`` switches; the cheaper, all switching only when it is cheaper by more than ``tie``.
    An unused alpha pays its cost when anyone moves to it. Each person's change is taken before summing, so the
    sums do not lose precision to large costs shared by both sides."""
    count, labels_count = cost.shape
    rows = np.arange(count)
    change = cost[:, alphas] - cost[rows, labels][:, None]  # (N, A); +inf: forbidden
    alone = (change < -tie) & (labels[:, None] != alphas[None, :])
    # Sums per used label over its members (people sorted by label; sums, not BLAS products: a 100 x 100 product
    # waits for BLAS's threads when other work keeps the cores busy, the sums do not).
    order = np.argsort(labels, kind="stable")
    used, starts = np.unique(labels[order], return_index=True)
    gain = np.add.reduceat(np.where(alone, change, 0.0)[order], starts, axis=0)  # (U, A) <= 0
    rest = np.add.reduceat(np.minimum(np.where(alone, 0.0, change), _FORBIDDEN)[order], starts, axis=0)
    itself = used[:, None] == alphas[None, :]  # the label expanded: its members stay
    whole_used = (rest < mdl - tie) & ~itself
    per_label = np.where(whole_used, gain + rest - mdl, np.where(itself, 0.0, gain))
    whole = np.zeros((labels_count, len(alphas)), dtype=bool)
    whole[used] = whole_used
    moved = whole_used.any(axis=0) | alone.any(axis=0)
    fresh = ~np.isin(alphas, used)
    delta = per_label.sum(axis=0) + np.where(moved & fresh, mdl, 0.0)
    return delta, whole, alone


def _apply(labels: np.ndarray, alpha: int, whole: np.ndarray, alone: np.ndarray) -> np.ndarray:
    """``labels`` after the expansion move on ``alpha`` (one column of ``_expansions``' whole and alone)."""
    moving = whole[labels] | alone
    return np.where(moving, alpha, labels)


def _best_moves(cost: np.ndarray, labels: np.ndarray, mdl: float) -> np.ndarray:
    """Steepest descent over expansion moves: repeatedly the move lowering the energy most (ties within 1e-9 mdl:
    the lowest label), until none lowers it by more than that."""
    tie = _TIE * mdl
    alphas = np.arange(cost.shape[1])
    # Each kept move lowers the energy by more than ``tie``; the bound only guards against an endless loop.
    for _ in range(10 * cost.size + 10):
        delta, whole, alone = _expansions(cost, labels, alphas, mdl, tie)
        best = float(delta.min())
        if not best < -tie:
            break
        alpha = int(np.flatnonzero(delta <= best + tie)[0])
        labels = _apply(labels, alpha, whole[:, alpha], alone[:, alpha])
    return labels


def _input_moves(cost: np.ndarray, labels: np.ndarray, mdl: float) -> np.ndarray:
    """The published detector's sweep: expand labels 0, 1, ... cyclically, keep each move that does not raise the
    energy, stop after as many expansions in a row as there are labels with no decrease (the one that decreased
    counts as the first). No tolerance: ties as the published code breaks them (nobody switches)."""
    labels_count = cost.shape[1]
    since = 0
    alpha = 0
    while True:
        delta, whole, alone = _expansions(cost, labels, np.array([alpha]), mdl, 0.0)
        change = float(delta[0])
        if change <= 0:
            labels = _apply(labels, alpha, whole[:, 0], alone[:, 0])
        since = 1 if change < 0 else since + 1
        if since >= labels_count:
            return labels
        alpha = (alpha + 1) % labels_count


def _refit(
    labels: np.ndarray, votes: np.ndarray, known: np.ndarray, owners: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The used labels renumbered 0.. in their old order, each centre the mean of its members' known votes; a label
    left without a known facing dissolves into its members' own labels (appended, by person). Returns the labels,
    the (K, 2) centres (NaN for an own label) and the owners (-1 for a centre)."""
    used, inverse = np.unique(labels, return_inverse=True)
    inverse = inverse.ravel()
    result = np.empty(len(labels), dtype=int)
    centres: list[np.ndarray] = []
    new_owners: list[int] = []
    dissolved: list[int] = []
    for k, old in enumerate(used.tolist()):
        members = inverse == k
        owner = int(owners[old])
        if owner < 0 and not known[members].any():
            dissolved += np.flatnonzero(members).tolist()
            continue
        result[members] = len(centres)
        centres.append(votes[members & known].mean(axis=0) if owner < 0 else np.full(2, np.nan))
        new_owners.append(owner)
    for person in sorted(dissolved):
        result[person] = len(centres)
        centres.append(np.full(2, np.nan))
        new_owners.append(person)
    return result, np.array(centres).reshape(-1, 2), np.array(new_owners, dtype=int)


def _canonical(labels: np.ndarray) -> np.ndarray:
    """Groups of two or more numbered 0.. by their lowest member index; -1 for people alone."""
    sizes = np.bincount(labels)
    result = np.full(len(labels), -1)
    number: dict[int, int] = {}
    for person, label in enumerate(labels.tolist()):
        if sizes[label] > 1:
            result[person] = number.setdefault(label, len(number))
    return result
