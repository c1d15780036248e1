"""The Python layer's cost (benches/python_layer.rs runs it): the same states as the Rust side,
through `thickness_collision.Checker`. Prints one JSON object: seconds per `check` call (one at a
time, reading `in_collision`), the Rust API's loop over the same rows in this process (before
each Python loop), and per batch (`check_batch`, flags and with depths)."""

import json
import sys
import time

import numpy as np

import thickness_collision as tc

params, states_path, rounds = sys.argv[1], sys.argv[2], int(sys.argv[3])
checker = tc.Checker.from_params(params)
q = np.fromfile(states_path, dtype="<f8").reshape(-1, len(checker.joint_names))
out = {"check": [], "rust_in_process": [], "batch_flags": [], "batch_depths": [], "colliding": 0}
for _ in range(rounds):
    # The Rust API's loop in this process, then the Python loop, on the same rows.
    seconds, colliding_rust = checker._time_rust_checks(q)
    out["rust_in_process"].append(seconds)
    started = time.perf_counter()
    colliding = 0
    for row in q:
        colliding += checker.check(row).in_collision
    out["check"].append((time.perf_counter() - started) / len(q))
    out["colliding"] = int(colliding)
    assert colliding == colliding_rust
    started = time.perf_counter()
    checker.check_batch(q)
    out["batch_flags"].append(time.perf_counter() - started)
    started = time.perf_counter()
    checker.check_batch(q, depths=True)
    out["batch_depths"].append(time.perf_counter() - started)
print(json.dumps(out))
