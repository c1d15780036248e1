#!/usr/bin/env python3
"""coal's BVH build on the build benchmark's wall: the peer beside `cargo bench --bench build`.

    python benches/coal_build.py WALL.bin [--repeat 5]

WALL.bin is written by `cargo run --release --example dump_wall -- WALL.bin` (the same
1,002,528-triangle wavy wall that benches/build.rs builds; both print the same checksum). Times
coal.BVHModelOBBRSS's beginModel / addVertices / addTriangles / endModel (endModel builds the
OBBRSS tree), median of --repeat runs, and, when python-fcl is installed, the same for
fcl.BVHModel (OBBRSS too). Reading the file and converting the arrays to the dtypes the bindings
take (float64 and int64, C order) is done once, before timing. The last line is machine-readable:
`COAL_BUILD {json}`.
"""
import argparse
import json
import statistics
import sys
import time

import numpy as np


def read_wall(path):
    with open(path, "rb") as f:
        if f.read(8) != b"TCWALL01":
            sys.exit(f"{path}: not a TCWALL01 file (write it with examples/dump_wall.rs)")
        nv, nt = np.frombuffer(f.read(16), dtype="<u8")
        v = np.frombuffer(f.read(int(nv) * 24), dtype="<f8").reshape(-1, 3)
        t = np.frombuffer(f.read(int(nt) * 12), dtype="<u4").reshape(-1, 3)
    return v, t


def checksum(v, t):
    """examples/dump_wall.rs's checksum: sum_k bits_k * (2k + 1) and sum_k index_k * (2k + 1), mod 2^64."""
    with np.errstate(over="ignore"):
        bits = np.ascontiguousarray(v).reshape(-1).view("<u8")
        w = 2 * np.arange(bits.size, dtype=np.uint64) + np.uint64(1)
        cv = int(np.sum(bits * w, dtype=np.uint64))
        idx = t.reshape(-1).astype(np.uint64)
        w = 2 * np.arange(idx.size, dtype=np.uint64) + np.uint64(1)
        ct = int(np.sum(idx * w, dtype=np.uint64))
    return cv, ct


def median_time(build, repeat):
    times, model = [], None
    for _ in range(repeat):
        model = None  # free the previous tree outside the timed region
        s = time.perf_counter()
        model = build()
        times.append(time.perf_counter() - s)
    return statistics.median(times), times, model


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("wall")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()

    import coal

    v, t = read_wall(args.wall)
    cv, ct = checksum(v, t)
    print(f"wall: {len(v)} vertices, {len(t)} triangles")
    print(f"checksum: vertices={cv:016x} triangles={ct:016x}")
    verts = np.ascontiguousarray(v, dtype=np.float64)
    tris = np.ascontiguousarray(t, dtype=np.int64)
    n = len(tris)

    def build_coal():
        m = coal.BVHModelOBBRSS()
        m.beginModel(n, len(verts))
        m.addVertices(verts)
        m.addTriangles(tris)
        m.endModel()
        return m

    med, times, model = median_time(build_coal, args.repeat)
    assert model.num_tris == n, (model.num_tris, n)
    mem = model.memUsage(False)
    out = {
        "coal_version": coal.__version__,
        "triangles": n,
        "coal_median_s": med,
        "coal_times_s": times,
        "coal_tris_per_s": n / med,
        "coal_bvs": model.getNumBVs(),
        "coal_bytes_per_triangle": mem / n,
    }
    print(f"coal {coal.__version__} BVHModelOBBRSS build: median {med * 1e3:.1f} ms of {args.repeat} "
          f"({', '.join(f'{x * 1e3:.0f}' for x in times)} ms), {n / med / 1e6:.2f} M triangles/s, "
          f"{model.getNumBVs()} BVs, memUsage {mem / n:.1f} B/triangle")
    del model

    try:
        import fcl
        from importlib.metadata import version
    except ImportError:
        fcl = None
    if fcl is not None:
        def build_fcl():
            m = fcl.BVHModel()
            m.beginModel(len(verts), n)
            m.addSubModel(verts, tris)
            m.endModel()
            return m

        med_f, times_f, model = median_time(build_fcl, args.repeat)
        assert model.num_tries_() == n
        del model
        out.update({"fcl_version": version("python-fcl"), "fcl_median_s": med_f, "fcl_times_s": times_f,
                    "fcl_tris_per_s": n / med_f})
        print(f"python-fcl {out['fcl_version']} BVHModel (OBBRSS) build: median {med_f * 1e3:.1f} ms of "
              f"{args.repeat} ({', '.join(f'{x * 1e3:.0f}' for x in times_f)} ms), {n / med_f / 1e6:.2f} M triangles/s")
    out.update({"checksum_vertices": f"{cv:016x}", "checksum_triangles": f"{ct:016x}"})
    print("COAL_BUILD " + json.dumps(out))


if __name__ == "__main__":
    main()
