"""G-MITRE: how well a partition of people into groups matches the true one, singletons included.

MITRE (Vilain et al. 1995, coreference scoring) counts links: the recall of a true partition is
sum over its classes S of (|S| - |p(S)|) / sum of (|S| - 1), where p(S) is S cut by the other partition (a person
in no class of the other partition is a part of their own); precision swaps the two. A partition of singletons has
no links, so G-MITRE (Solera et al., TPAMI 2016) gives every singleton a copy of its own on the same side before
counting: someone alone on both sides is a correct link, alone on one side only a missed one.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from sid.errors import InputError

__all__ = ["LinkCounts", "gmitre_counts"]


@dataclass(frozen=True)
class LinkCounts:
    """Correct and total links of both sides: recall = recall_hits / recall_links, precision likewise; add the
    counts of several frames to pool them."""

    recall_hits: int = 0
    recall_links: int = 0
    precision_hits: int = 0
    precision_links: int = 0

    def __add__(self, other: LinkCounts) -> LinkCounts:
        return LinkCounts(
            self.recall_hits + other.recall_hits,
            self.recall_links + other.recall_links,
            self.precision_hits + other.precision_hits,
            self.precision_links + other.precision_links,
        )

    @property
    def recall(self) -> float:
        return self.recall_hits / self.recall_links if self.recall_links else 1.0

    @property
    def precision(self) -> float:
        return self.precision_hits / self.precision_links if self.precision_links else 1.0

    @property
    def f1(self) -> float:
        p, r = self.precision, self.recall
        return 2 * p * r / (p + r) if p + r > 0 else 0.0


def gmitre_counts(truth: Iterable[Iterable[int]], found: Iterable[Iterable[int]]) -> LinkCounts:
    """G-MITRE link counts of the ``found`` groups against the ``truth`` groups over the same people: each side a
    partition (disjoint member-id sets, singletons included; a person listed on one side only is alone on the
    other)."""
    true_classes = _partition(truth, "truth")
    found_classes = _partition(found, "found")
    true_people = frozenset().union(*true_classes)
    found_people = frozenset().union(*found_classes)
    true_classes += [frozenset({i}) for i in sorted(found_people - true_people)]
    found_classes += [frozenset({i}) for i in sorted(true_people - found_people)]
    hits, links = _links(true_classes, found_classes)
    precision_hits, precision_links = _links(found_classes, true_classes)
    return LinkCounts(hits, links, precision_hits, precision_links)


def _partition(groups: Iterable[Iterable[int]], side: str) -> list[frozenset[int]]:
    classes = [frozenset(g) for g in groups]
    seen: set[int] = set()
    for c in classes:
        if seen & c:
            raise InputError(f"gmitre: person {min(seen & c)} is in two {side} groups")
        seen |= c
    return [c for c in classes if c]


def _links(classes: list[frozenset[int]], other: list[frozenset[int]]) -> tuple[int, int]:
    """Correct and total links of ``classes`` cut by ``other``, singletons doubled (G-MITRE)."""
    owner = {m: k for k, c in enumerate(other) for m in c}
    alone_other = {k for k, c in enumerate(other) if len(c) == 1}
    hits = links = 0
    for c in classes:
        if len(c) == 1:  # {i} -> {i, i'}: whole when i is alone on the other side too (with its own copy)
            (person,) = c
            links += 1
            hits += person not in owner or owner[person] in alone_other
            continue
        parts = len({owner.get(m, ("alone", m)) for m in c})
        links += len(c) - 1
        hits += len(c) - parts
    return hits, links
