"""Every call against the command line on the same inputs: the CLI's files read back by the
package (`Estimate.from_json`, `Design.from_json`, …) against the package's own call.
Joint values go through CSV files in degrees with 4 decimals, which both sides convert to
radians by the same `x * (π / 180)`: the inputs are the same bits."""

import json

import numpy as np
import pytest

import armcal
from conftest import PAPER_CELL, read_data, write_poses

TIGHT = dict(rtol=1e-12, atol=1e-12)


def test_identify_matches_cli(cli, cell, simulated):
    d, _ = simulated
    cli("identify", "--cell", PAPER_CELL, "--data", d / "data.csv", "--out", d / "est.json",
        "--quiet")
    theirs = armcal.Estimate.from_json((d / "est.json").read_text())
    q, measured = read_data(d / "data.csv", cell.dof)
    ours = armcal.identify(cell, q, measured)
    assert ours.converged and ours.status == theirs.status
    assert ours.names == theirs.names and ours.free == theirs.free
    np.testing.assert_allclose(ours.params, theirs.params, **TIGHT)
    np.testing.assert_allclose(ours.sigma, theirs.sigma, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(ours.cov, theirs.cov, rtol=1e-9, atol=1e-18)
    np.testing.assert_allclose(ours.tcp_cov, theirs.tcp_cov, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(ours.residuals, theirs.residuals, **TIGHT)
    assert ours.tcp_cov.shape == (len(cell.working_poses()), 3, 3)
    assert ours.residuals.shape == (len(q), 3)


def test_identify_holdout_robust_matches_cli(cli, cell, simulated):
    d, _ = simulated
    cli("identify", "--cell", PAPER_CELL, "--data", d / "data.csv", "--out", d / "est-h.json",
        "--holdout", 0.25, "--robust", "huber", "--seed", 4, "--quiet")
    theirs = armcal.Estimate.from_json((d / "est-h.json").read_text())
    q, measured = read_data(d / "data.csv", cell.dof)
    ours = armcal.identify(cell, q, measured, holdout=0.25, robust="huber", seed=4)
    np.testing.assert_allclose(ours.params, theirs.params, **TIGHT)
    assert ours.validation["test_ids"] == theirs.validation["test_ids"]
    assert ours.validation["calibrated"] == pytest.approx(theirs.validation["calibrated"], rel=1e-9)


def test_simulate_matches_cli(cell, simulated):
    """The CLI's data file holds 9 decimals (mm): the comparison is to that precision."""
    d, q_deg = simulated
    truth = json.loads((d / "truth.json").read_text())
    by_name = {p["name"]: p for p in truth["parameters"]}
    to_internal = {"mm": lambda v: v, "": lambda v: v, "deg": np.radians}
    params = [to_internal[p["unit"]](by_name[p["name"]]["truth"]) for p in cell.parameters()]
    data = armcal.simulate(cell, np.radians(q_deg), truth=np.array(params), seed=3 + 0x5EED)
    q, measured = read_data(d / "data.csv", cell.dof)
    np.testing.assert_array_equal(data.q, q)
    np.testing.assert_allclose(data.measured, measured, rtol=0, atol=1e-8)


def test_predict_and_fk_match_cli(cli, cell, tmp_path):
    q_deg = np.array([[10.0, -20.0, 30.0, 40.0, -50.0, 60.0], [0.0, 5.0, 10.0, -15.0, 20.0, 0.5]])
    write_poses(tmp_path / "poses.csv", q_deg)
    cli("predict", "--cell", PAPER_CELL, "--joints", tmp_path / "poses.csv",
        "--out", tmp_path / "pred.csv")
    ours = armcal.predict(cell, np.radians(q_deg))
    _, theirs = read_data(tmp_path / "pred.csv", cell.dof)
    np.testing.assert_allclose(ours.measured, theirs, rtol=0, atol=1e-8)  # 9 decimals in CSV
    # Noise-free simulation with the nominal is the same prediction, bit for bit.
    sim = armcal.simulate(cell, np.radians(q_deg), noise=False)
    np.testing.assert_array_equal(sim.measured, ours.measured)
    # fk: the CLI's JSON holds the tool frame's world position (mm) at full precision.
    tool = armcal.fk(cell, np.radians(q_deg))
    assert tool.shape == (2, 4, 4)
    for row, pose in zip(q_deg, tool):
        out = json.loads(cli("fk", PAPER_CELL, "--joints",
                             ",".join(repr(float(v)) for v in row), "--json"))
        tcp = [f for f in out["frames_world"] if f["frame"] in ("tool", "tcp")][-1]
        np.testing.assert_allclose(pose[:3, 3], tcp["pose"]["xyz_mm"], **TIGHT)
        np.testing.assert_allclose(pose[3], [0, 0, 0, 1], **TIGHT)


def test_plan_matches_cli(cli, cell, tmp_path):
    cli("plan", "--cell", PAPER_CELL, "--poses", 12, "--collisions", "off", "--seed", 2,
        "--out", tmp_path / "design.csv", "--report", tmp_path / "design.json", "--quiet")
    theirs = armcal.Design.from_json((tmp_path / "design.json").read_text())
    ours = armcal.plan(cell, 12, collisions=False, seed=2)
    assert ours.q.shape == (12, cell.dof)
    np.testing.assert_allclose(ours.q, theirs.q, **TIGHT)
    assert ours.value == pytest.approx(theirs.value, rel=1e-12)
    assert ours.status == theirs.status
    np.testing.assert_allclose(ours.sigma, theirs.sigma, rtol=1e-9)


def test_plan_from_pool(cell):
    pool = np.radians(np.loadtxt(PAPER_CELL.parent / "paper-pool-500.csv", delimiter=",",
                                 skiprows=1, usecols=range(1, 7)))
    design = armcal.plan(cell, 30, pool=pool, collisions=False)
    chosen = {tuple(r) for r in np.round(design.q, 9)}
    assert chosen <= {tuple(r) for r in np.round(pool, 9)}
    assert len(chosen) == 30


def test_check_and_compensate_match_cli(cli, cell, simulated, tmp_path):
    d, _ = simulated
    est_path = d / "est.json"
    if not est_path.exists():
        cli("identify", "--cell", PAPER_CELL, "--data", d / "data.csv", "--out", est_path,
            "--quiet")
    est = armcal.Estimate.from_json(est_path.read_text())
    # check: the same robot measured again at other poses does not drift.
    cli("check", "--cell", PAPER_CELL, "--estimate", est_path, "--data", d / "data.csv",
        "--out", tmp_path / "check.json")
    theirs = json.loads((tmp_path / "check.json").read_text())
    q, measured = read_data(d / "data.csv", cell.dof)
    ours = armcal.check(cell, est, q, measured)
    assert ours.moved_groups() == armcal.DriftCheck.from_json(json.dumps(theirs)).moved_groups()
    assert json.loads(ours.to_json()).keys() == theirs.keys()
    # compensate a joint program.
    program = np.array([[10.0, -20.0, 30.0, 40.0, -50.0, 60.0], [5.0, 5.0, 10.0, -15.0, 20.0, 1.0]])
    write_poses(tmp_path / "program.csv", program)
    cli("compensate", "--cell", PAPER_CELL, "--estimate", est_path, "--targets",
        tmp_path / "program.csv", "--out", tmp_path / "out.csv")
    out = armcal.compensate(cell, est, np.radians(program))
    assert out["status"] == ["converged", "converged"]
    theirs_q = np.loadtxt(tmp_path / "out.csv", delimiter=",", skiprows=1, usecols=range(1, 7))
    np.testing.assert_allclose(np.degrees(out["q"]), theirs_q, rtol=0, atol=1e-6)  # 6 decimals
