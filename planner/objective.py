"""The OMPL optimisation objective: path length plus the weighted integral of cell cost (``planner.problem``).

The class derives from ``ob.PathLengthOptimizationObjective`` (an ``ob.OptimizationObjective``) and overrides
``motionCost`` (J of the straight motion) and ``motionCostHeuristic`` (its length) in Python. The rest stays in
C++ and stays correct for J because J >= path length:
- the cost-to-go heuristic is the straight-line distance to the goal, an admissible lower bound of J (a Python
  subclass of the plain base class cannot set one in ompl 2.0.1's bindings, and without one informed sampling
  and BIT*'s ordering lose their guidance);
- the informed sampler samples the ellipse of states whose distance through them is below the best cost, a
  superset of the states that can improve J, so no improving state is excluded.
``motionCostHeuristic`` must be overridden: PathLength's own returns ``motionCost``, which under J is no lower bound
(the straight line through a social zone costs more than the detour around it), and BIT* then stops after its
first solution, believing it optimal (docs/parameters.md).
(``StateCostIntegralObjective`` subclasses are not an option: ompl 2.0.1 ignores their Python ``stateCost``.)
"""

from __future__ import annotations

import math

from ompl import base as ob

from planner.problem import CostField

__all__ = ["CostmapObjective"]


class CostmapObjective(ob.PathLengthOptimizationObjective):
    """J = integral of (1 + w c / 252) ds over the motion, from ``CostField.segment_cost``; returns ``ob.Cost``."""

    def __init__(self, si: ob.SpaceInformation, field: CostField) -> None:
        super().__init__(si)
        self._segment_cost = field.segment_cost

    def motionCost(self, s1: ob.State, s2: ob.State) -> ob.Cost:  # noqa: N802 (OMPL's name)
        return ob.Cost(self._segment_cost(s1[0], s1[1], s2[0], s2[1]))

    def motionCostHeuristic(self, s1: ob.State, s2: ob.State) -> ob.Cost:  # noqa: N802 (OMPL's name)
        return ob.Cost(math.hypot(s2[0] - s1[0], s2[1] - s1[1]))
