"""Shared fixtures of the Python package's tests: the repository, the `armcal` command line
(to compare the package with on the same inputs), the paper cell and a small data set."""

import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

import armcal

ROOT = pathlib.Path(__file__).resolve().parents[3]
PAPER_CELL = ROOT / "examples" / "paper-cell.toml"


def cli_binary():
    """The `armcal` binary: $ARMCAL_BIN, else the workspace's release or debug build."""
    if os.environ.get("ARMCAL_BIN"):
        return os.environ["ARMCAL_BIN"]
    for profile in ("release", "debug"):
        path = ROOT / "target" / profile / "armcal"
        if path.exists():
            return str(path)
    return shutil.which("armcal")


@pytest.fixture(scope="session")
def cli():
    """Runs the command line; fails the test (with its stderr) if the command fails."""
    binary = cli_binary()
    if binary is None:
        pytest.fail("no armcal binary: build it (cargo build --release) or set ARMCAL_BIN")

    def run(*args, cwd=None):
        done = subprocess.run(
            [binary, *map(str, args)], cwd=cwd, capture_output=True, text=True
        )
        assert done.returncode == 0, f"armcal {' '.join(map(str, args))}: {done.stderr}"
        return done.stdout

    return run


@pytest.fixture(scope="session")
def cell():
    return armcal.Cell.load(str(PAPER_CELL))


def random_poses_deg(cell, n, seed):
    """n random joint rows within the limits, degrees rounded to 1e-4 (exact in a CSV)."""
    lo, hi = cell.joint_limits()
    rng = np.random.default_rng(seed)
    q = rng.uniform(np.degrees(lo) * 0.9, np.degrees(hi) * 0.9, size=(n, cell.dof))
    return np.round(q, 4)


def write_poses(path, q_deg):
    with open(path, "w") as f:
        f.write("pose_id," + ",".join(f"q{j + 1}_deg" for j in range(q_deg.shape[1])) + "\n")
        for i, row in enumerate(q_deg):
            f.write(f"{i + 1}," + ",".join(repr(float(v)) for v in row) + "\n")


def read_data(path, dof):
    """A position data file the CLI wrote: q (rad, converted as armcal does), measured (mm)."""
    with open(path) as f:
        header = f.readline().strip().split(",")
    qcols = [header.index(f"q{j + 1}_deg") for j in range(dof)]
    xcols = [header.index(c) for c in ("x_mm", "y_mm", "z_mm")]
    table = np.loadtxt(path, delimiter=",", skiprows=1, usecols=qcols + xcols, ndmin=2)
    # f64::to_radians is x * (π / 180), as numpy's radians: the same bits as the CLI's.
    return np.radians(table[:, :dof]), table[:, dof:]


@pytest.fixture(scope="session")
def simulated(tmp_path_factory, cli, cell):
    """The 60 KPI poses planned for the paper cell simulated by the CLI (seed 3): the folder
    (poses.csv, data.csv, truth.json) and the poses (deg)."""
    d = tmp_path_factory.mktemp("sim")
    q_deg = np.loadtxt(ROOT / "examples" / "paper-poses-planned-60.csv", delimiter=",",
                       skiprows=1, usecols=range(1, 7))
    write_poses(d / "poses.csv", q_deg)
    cli("simulate", "--cell", PAPER_CELL, "--poses", d / "poses.csv", "--seed", 3,
        "--allow-unmeasurable",
        "--out", d / "data.csv", "--truth-out", d / "truth.json")
    return d, q_deg
