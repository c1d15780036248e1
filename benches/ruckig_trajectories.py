"""Time-parameterised Panda trajectories for benches/trajectory.rs, from ruckig (PyPI `ruckig`,
the jerk-limited generator MoveIt 2 ships as a time parameterisation): each one a chain of
ruckig legs through random waypoints (each joint 0.2-0.6 rad from the last, inside the limits,
at rest at each waypoint), sampled at `points` evenly spaced instants with positions,
velocities and accelerations, as MoveIt hands a trajectory to the controller.

Usage: ruckig_trajectories.py COUNT POINTS SEED OUT.json
Writes a JSON list of {"t": [s...], "p": [[rad x 7]...], "v": [...], "a": [...]}.
"""
import json
import random
import sys

from ruckig import InputParameter, Result, Ruckig, Trajectory

# panda_joint1..7 limits (example-robot-data's panda.urdf), with a margin.
LIMITS = [(-2.8, 2.8), (-1.7, 1.7), (-2.8, 2.8), (-3.0, -0.1), (-2.8, 2.8), (0.0, 3.7), (-2.8, 2.8)]
VEL = [2.1, 2.1, 2.1, 2.1, 2.6, 2.6, 2.6]
ACC = [3.0] * 7
JERK = [30.0] * 7

count, points, seed, out = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
rng = random.Random(seed)
result = []
for _ in range(count):
    q = [rng.uniform(lo, hi) for lo, hi in LIMITS]
    legs = []
    for _ in range(4):
        target = [min(hi, max(lo, x + rng.choice([-1, 1]) * rng.uniform(0.2, 0.6))) for x, (lo, hi) in zip(q, LIMITS)]
        inp = InputParameter(7)
        inp.current_position, inp.current_velocity, inp.current_acceleration = q, [0.0] * 7, [0.0] * 7
        inp.target_position, inp.target_velocity, inp.target_acceleration = target, [0.0] * 7, [0.0] * 7
        inp.max_velocity, inp.max_acceleration, inp.max_jerk = VEL, ACC, JERK
        traj = Trajectory(7)
        assert Ruckig(7).calculate(inp, traj) in (Result.Working, Result.Finished)
        legs.append(traj)
        q = target
    total = sum(t.duration for t in legs)
    sample = {"t": [], "p": [], "v": [], "a": []}
    for k in range(points):
        t = total * k / (points - 1)
        rest = t
        for leg in legs:
            if rest <= leg.duration or leg is legs[-1]:
                p, v, a = leg.at_time(min(rest, leg.duration))
                break
            rest -= leg.duration
        sample["t"].append(t)
        sample["p"].append(list(p))
        sample["v"].append(list(v))
        sample["a"].append(list(a))
    result.append(sample)
with open(out, "w") as f:
    json.dump(result, f)
