"""The OMPL integration: the state space, the validators, and plans that never cross a sheet."""

import numpy as np
import pytest

import thickness_collision as tc
from thickness_collision import ompl as tco
from ompl import base as ob
from ompl import geometric as og


def set_state(space, values):
    s = space.allocState()
    for i, v in enumerate(values):
        s[i] = float(v)
    return s


def test_state_space_bounds_are_the_joint_limits(panda):
    space = tco.state_space(panda)
    lo, hi = panda.limits
    b = space.getBounds()
    assert space.getDimension() == len(panda.joint_names)
    assert [b.low[i] for i in range(len(lo))] == list(lo) and [b.high[i] for i in range(len(hi))] == list(hi)


def test_validators_agree_with_the_checker(panda):
    space = tco.state_space(panda)
    si = ob.SpaceInformation(space)
    svc, mv = tco.StateValidityChecker(si, panda), tco.MotionValidator(si, panda)
    rng = np.random.default_rng(9)
    lo, hi = panda.limits
    for _ in range(100):
        a, b = lo + (hi - lo) * rng.random(len(lo)), lo + (hi - lo) * rng.random(len(lo))
        b = a + np.clip(b - a, -0.5, 0.5)
        sa, sb = set_state(space, a), set_state(space, b)
        assert svc.isValid(sa) == (not panda.check(a).in_collision)
        assert mv.checkMotion(sa, sb) == (not panda.check_motion(a, b).in_collision)


def test_rrtconnect_plans_are_certified(panda):
    space = tco.state_space(panda)
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    ss.setStateValidityChecker(tco.StateValidityChecker(si, panda))
    si.setMotionValidator(tco.MotionValidator(si, panda))
    rng = np.random.default_rng(10)
    lo, hi = panda.limits

    def free_state():
        while True:
            q = lo + (hi - lo) * rng.random(len(lo))
            if not panda.check(q).in_collision:
                return q

    solved = 0
    for _ in range(3):
        start, goal = free_state(), free_state()
        ss.clear()
        ss.setStartAndGoalStates(set_state(space, start), set_state(space, goal))
        ss.setPlanner(og.RRTConnect(si))
        if not ss.solve(5.0) or not ss.haveExactSolutionPath():
            continue
        solved += 1
        path = ss.getSolutionPath()
        states = np.array([[path.getState(k)[i] for i in range(len(lo))] for k in range(path.getStateCount())])
        for r in panda.check_path(states):
            assert not r.in_collision, r.to_dict()
    assert solved >= 1
