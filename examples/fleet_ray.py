#!/usr/bin/env python3
"""A fleet of robots calibrated on Ray: each robot is one Ray task running armcal's
per-robot calibration (`armcal.fleet_task`: plan its KPI design, simulate its campaign
with the cell's instrument noise, identify, check on held-out poses, optionally write its
design, estimate and report), the rows gathered into one fleet table (CSV) and a fleet
summary page (HTML).

The fleet is N virtual copies of a built-in robot or cell file, robot i perturbed with
seed `--seed + i` (armcal's seeded perturbation of the nominal model).

    python examples/fleet_ray.py --robots 90 --out fleet            # local Ray
    python examples/fleet_ray.py --address ray://head:10001 --robots 500 --out fleet
    python examples/fleet_ray.py --in-process --robots 90 --out fleet   # armcal.fleet, no Ray

Each task runs with RAYON_NUM_THREADS=1 (its runtime env), so Ray's one CPU per task is
one thread and the workers do not oversubscribe the cores. On a cluster, every node needs
the armcal package installed (`pip install ./crates/armcal-py`) and the cell: a built-in
robot name, or a cell file at the same path on every node.
"""

import argparse
import csv
import html
import os
import pathlib
import sys
import time

import armcal

COLUMNS = [
    "robot", "seed", "plan_value", "status", "converged", "chi2", "fit_rms_mm",
    "tcp_sigma_mm", "check_rms_mm", "check_max_mm", "nominal_rms_mm", "check_moved", "plan_s", "identify_s",
    "total_s", "report", "error",
]


def parse(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--cell", default="examples/paper-cell.toml",
                   help="cell file or built-in robot (default: the paper's cell)")
    p.add_argument("--robots", type=int, default=8, help="fleet size N")
    p.add_argument("--seed", type=int, default=1, help="robot i has seed SEED + i")
    p.add_argument("--poses", type=int, default=60, help="poses of each robot's KPI design")
    p.add_argument("--collisions", action="store_true", help="plan with the cell's obstacles")
    p.add_argument("--reports", action="store_true", help="write every robot's report too")
    p.add_argument("--out", default="fleet", help="folder of fleet.csv and fleet.html")
    p.add_argument("--address", default=None,
                   help="a Ray cluster to join (default: start a local Ray)")
    p.add_argument("--workers", type=int, default=None,
                   help="CPUs of the local Ray (default: all)")
    p.add_argument("--in-process", action="store_true",
                   help="no Ray: armcal.fleet over rayon in this process")
    return p.parse_args(argv)


def run_ray(args, out):
    import ray

    if args.address:
        ray.init(address=args.address)
    else:
        ray.init(num_cpus=args.workers, include_dashboard=False)
    robot_out = str(out / "robots") if args.reports else None

    @ray.remote(num_cpus=1, runtime_env={"env_vars": {"RAYON_NUM_THREADS": "1"}})
    def calibrate(cell_source, seed):
        cell = armcal.Cell.load(cell_source)
        return armcal.fleet_task(cell, seed, poses=args.poses, collisions=args.collisions,
                                 out=robot_out)

    cell_source = os.path.abspath(args.cell) if os.path.exists(args.cell) else args.cell
    started = time.perf_counter()
    rows = ray.get([calibrate.remote(cell_source, args.seed + i) for i in range(args.robots)])
    wall = time.perf_counter() - started
    ray.shutdown()
    return rows, wall


def run_in_process(args, out):
    cell = armcal.Cell.load(args.cell)
    started = time.perf_counter()
    rows = armcal.fleet([cell] * args.robots, seed=args.seed, poses=args.poses,
                        collisions=args.collisions,
                        out=str(out / "robots") if args.reports else None)
    return rows, time.perf_counter() - started


def write_table(rows, path):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") if r.get(k) is not None else "" for k in COLUMNS})


def summary(rows, wall, how):
    ok = [r for r in rows if r.get("error") is None]
    calibrated = [r for r in ok if r["converged"]]
    task_s = sum(r["total_s"] for r in ok)
    lines = [
        f"{len(rows)} robots ({how}): {len(calibrated)} calibrated, "
        f"{len(ok) - len(calibrated)} not converged, {len(rows) - len(ok)} failed",
        f"wall {wall:.2f} s; the tasks' own time {task_s:.2f} s",
    ]
    if calibrated:
        worst = max(calibrated, key=lambda r: r["check_max_mm"])
        rms = sorted(r["check_rms_mm"] for r in calibrated)
        nominal = sorted(r["nominal_rms_mm"] for r in calibrated)
        lines.append(
            f"held-out error: median RMS {nominal[len(nominal) // 2]:.3f} mm nominal → "
            f"{rms[len(rms) // 2]:.3f} mm calibrated; largest {worst['check_max_mm']:.3f} mm "
            f"({worst['robot']})")
        moved = [r["robot"] for r in calibrated if r["check_moved"]]
        lines.append(f"drift check on held-out poses: {len(moved)} robots flagged"
                     + (f" ({', '.join(moved)})" if moved else ""))
    return lines


def write_page(rows, lines, path):
    head = "".join(f"<th>{html.escape(c)}</th>" for c in COLUMNS[:-2])
    body = []
    for r in rows:
        cells = []
        for c in COLUMNS[:-2]:
            v = r.get(c)
            text = f"{v:.4g}" if isinstance(v, float) else ("" if v is None else str(v))
            if c == "robot" and r.get("report"):
                rel = os.path.relpath(r["report"], path.parent)
                text = f'<a href="{html.escape(rel)}">{html.escape(text)}</a>'
            else:
                text = html.escape(text)
            cells.append(f"<td>{text}</td>")
        if r.get("error"):
            cells.append(f'<td colspan="99">{html.escape(r["error"])}</td>')
        body.append("<tr>" + "".join(cells) + "</tr>")
    items = "".join(f"<li>{html.escape(line)}</li>" for line in lines)
    path.write_text(
        "<!doctype html><meta charset='utf-8'><title>armcal fleet</title>"
        "<style>body{font-family:sans-serif}td,th{padding:2px 8px;text-align:right}</style>"
        f"<h1>armcal fleet</h1><ul>{items}</ul><table><tr>{head}</tr>{''.join(body)}</table>")


def main(argv=None):
    args = parse(argv if argv is not None else sys.argv[1:])
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.in_process:
        rows, wall = run_in_process(args, out)
        how = f"in-process, {os.environ.get('RAYON_NUM_THREADS', 'all')} rayon threads"
    else:
        rows, wall = run_ray(args, out)
        how = f"Ray at {args.address}" if args.address else (
            f"local Ray, {args.workers or os.cpu_count()} workers")
    rows.sort(key=lambda r: r["seed"])
    write_table(rows, out / "fleet.csv")
    lines = summary(rows, wall, how)
    write_page(rows, lines, out / "fleet.html")
    for line in lines:
        print(line)
    print(f"fleet table → {out / 'fleet.csv'}, summary → {out / 'fleet.html'}")
    return 0 if all(r.get("error") is None for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
