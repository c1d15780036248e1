"""OMPL validators backed by this package's checks (``pip install thickness_collision[ompl]``).

``MotionValidator`` is the guaranteed motion check: a motion it accepts touches nothing at any
instant, so OMPL's ``longest_valid_segment_fraction`` no longer decides what is missed. The state
space is a ``RealVectorStateSpace`` over ``checker.joint_names``, bounded by ``checker.limits``;
a continuous joint gets one turn, ``[-pi, pi]``, with no wrap-around (OMPL interpolates it
straight, and the motion validator checks that straight line, splitting it so that no piece
turns a joint by pi or more, where the checker would take the shorter arc).
"""

import math

from ompl import base as ob

__all__ = ["state_space", "StateValidityChecker", "MotionValidator"]


def state_space(checker):
    """A ``RealVectorStateSpace`` over ``checker.joint_names``, bounded by its limits."""
    names = checker.joint_names
    lower, upper = checker.limits
    space = ob.RealVectorStateSpace(len(names))
    bounds = ob.RealVectorBounds(len(names))
    for i in range(len(names)):
        bounds.setLow(i, float(lower[i]))
        bounds.setHigh(i, float(upper[i]))
    space.setBounds(bounds)
    for i, name in enumerate(names):
        space.setDimensionName(i, name)
    return space


def _values(state, dof):
    return [state[i] for i in range(dof)]


class StateValidityChecker(ob.StateValidityChecker):
    """A state is valid when ``checker.check`` finds it free."""

    def __init__(self, si, checker):
        super().__init__(si)
        self._checker = checker
        self._dof = len(checker.joint_names)

    def isValid(self, state):
        return not self._checker.check(_values(state, self._dof)).in_collision


class MotionValidator(ob.MotionValidator):
    """A motion is valid when the guaranteed motion check finds the straight line free."""

    def __init__(self, si, checker):
        super().__init__(si)
        self._checker = checker
        self._dof = len(checker.joint_names)

    def checkMotion(self, s1, s2, last_valid=None):
        a, b = _values(s1, self._dof), _values(s2, self._dof)
        # No piece may turn a joint by pi or more: the checker would take a continuous joint's
        # shorter arc, not the straight line OMPL interpolates.
        turn = max((abs(y - x) for x, y in zip(a, b)), default=0.0)
        pieces = max(1, math.ceil(turn / 3.0))
        if pieces == 1:
            return not self._checker.check_motion(a, b).in_collision
        path = [[x + (y - x) * k / pieces for x, y in zip(a, b)] for k in range(pieces + 1)]
        return not any(r.in_collision for r in self._checker.check_path(path))
