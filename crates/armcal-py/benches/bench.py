#!/usr/bin/env python3
"""Benchmarks of the Python package (docs/src/reference/benchmarks.md):

  identify   Python `identify` on 1000 simulated poses of the paper cell (27 free
             parameters), wall time of the call, against the Levenberg–Marquardt time the
             library itself records in the estimate (`solver.time_ms`) and against the
             library's `cargo bench -p armcal --bench identification` figure.
  fleet      the fleet of N robots (KPI plan, simulate, identify, check) in-process over
             rayon with the given RAYON_NUM_THREADS, and on a local Ray with 1 and 2
             workers (examples/fleet_ray.py): wall times, speed-up, per-task overhead.

    .venv-py/bin/python crates/armcal-py/benches/bench.py identify
    .venv-py/bin/python crates/armcal-py/benches/bench.py fleet --robots 90
"""

import argparse
import os
import pathlib
import statistics
import subprocess
import sys
import time

import numpy as np

import armcal

ROOT = pathlib.Path(__file__).resolve().parents[3]


def bench_identify(repeats):
    cell = armcal.Cell.load(str(ROOT / "examples" / "paper-cell.toml"))
    lo, hi = cell.joint_limits()
    q = np.random.default_rng(2).uniform(lo, hi, size=(1000, cell.dof))
    data = armcal.simulate(cell, q, truth=armcal.perturbed_truth(cell, seed=1), seed=3)
    walls, lm = [], []
    for _ in range(repeats):
        t = time.perf_counter()
        est = armcal.identify(cell, data)
        walls.append(time.perf_counter() - t)
        lm.append(est.to_dict()["solver"]["time_ms"])
        assert est.converged
    print(f"identify, 1000 poses, {len(est.free)} free parameters, {repeats} runs: "
          f"Python call median {1e3 * statistics.median(walls):.1f} ms "
          f"(min {1e3 * min(walls):.1f}); the library's LM inside it median "
          f"{statistics.median(lm):.1f} ms")


def bench_fleet(robots, poses):
    cell = armcal.Cell.load(str(ROOT / "examples" / "paper-cell.toml"))
    results = {}
    for threads in ("1", "2"):
        env = dict(os.environ, RAYON_NUM_THREADS=threads)
        code = (f"import armcal,time; c=armcal.Cell.load({str(ROOT / 'examples' / 'paper-cell.toml')!r});"
                f"t=time.perf_counter(); r=armcal.fleet([c]*{robots}, poses={poses});"
                "w=time.perf_counter()-t; print(w, sum(x['total_s'] for x in r))")
        out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                             text=True, check=True).stdout.split()
        results[f"in-process, {threads} thread(s)"] = (float(out[0]), float(out[1]))
    for workers in (1, 2):
        t = time.perf_counter()
        done = subprocess.run(
            [sys.executable, str(ROOT / "examples" / "fleet_ray.py"), "--robots", str(robots),
             "--poses", str(poses), "--workers", str(workers), "--out",
             f"/tmp/armcal-fleet-bench-{workers}"], capture_output=True, text=True, check=True)
        wall = next(float(line.split()[1]) for line in done.stdout.splitlines()
                    if line.startswith("wall"))
        task = next(float(line.split()[-2]) for line in done.stdout.splitlines()
                    if line.startswith("wall"))
        results[f"Ray, {workers} worker(s)"] = (wall, task)
        print(f"(Ray {workers}: whole script {time.perf_counter() - t:.1f} s)")
    base = results["in-process, 1 thread(s)"][0]
    for name, (wall, task) in results.items():
        print(f"{name}: wall {wall:.2f} s, speed-up {base / wall:.2f}x vs in-process 1 thread, "
              f"tasks' own time {task:.2f} s, overhead per robot "
              f"{1e3 * (wall * (2 if '2' in name else 1) - task) / robots:.1f} ms")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("what", choices=["identify", "fleet"])
    p.add_argument("--robots", type=int, default=90)
    p.add_argument("--poses", type=int, default=30)
    p.add_argument("--repeats", type=int, default=10)
    a = p.parse_args()
    if a.what == "identify":
        bench_identify(a.repeats)
    else:
        bench_fleet(a.robots, a.poses)


if __name__ == "__main__":
    main()
