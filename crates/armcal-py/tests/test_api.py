"""The package's own behaviour: bad input raises ArmcalError naming the field, every record
pickles, the GIL is released while armcal computes, progress callbacks, parameters, the
campaign and the report."""

import pickle
import threading
import time

import numpy as np
import pytest

import armcal
from conftest import PAPER_CELL, random_poses_deg


@pytest.fixture(scope="module")
def fitted(cell):
    q = np.radians(random_poses_deg(cell, 30, 5))
    truth = armcal.perturbed_truth(cell, seed=7)
    data = armcal.simulate(cell, q, truth=truth, seed=8)
    return q, data, armcal.identify(cell, data)


def test_error_is_a_value_error_naming_the_field(cell):
    assert issubclass(armcal.ArmcalError, ValueError)
    q = np.zeros((3, cell.dof))
    with pytest.raises(armcal.ArmcalError, match=r"q: expected an array of shape \(n, 6\).*got shape \[3, 5\]"):
        armcal.fk(cell, np.zeros((3, 5)))
    bad = np.zeros((3, 3))
    bad[1, 2] = np.nan
    with pytest.raises(armcal.ArmcalError, match=r"row 2, measured\[2\]"):
        armcal.identify(cell, q, bad)
    far = q.copy()
    far[2, 1] = 90.0  # degrees given as radians: a unit mistake
    with pytest.raises(armcal.ArmcalError, match=r"row 3"):
        armcal.dataset(cell, far, np.zeros((3, 3)))
    with pytest.raises(armcal.ArmcalError, match=r"method: unknown variant `newton`"):
        armcal.identify(cell, q, np.zeros((3, 3)), method="newton")
    with pytest.raises(armcal.ArmcalError, match=r"criterion: unknown `e-opt`, expected one of"):
        armcal.plan(cell, 5, criterion="e-opt")
    with pytest.raises(armcal.ArmcalError, match=r"holdout: a fraction in \[0, 1\)"):
        armcal.identify(cell, q, np.zeros((3, 3)), holdout=1.5)
    with pytest.raises(armcal.ArmcalError, match=r"params: expected an array of shape \(\d+,\)"):
        armcal.fk(cell, q, params=np.zeros(3))


def test_cell_file_errors_name_file_line_field(tmp_path):
    text = PAPER_CELL.read_text().replace("[robot]", "[robot]\nbogus_field = 3", 1)
    path = tmp_path / "bad-cell.toml"
    path.write_text(text)
    with pytest.raises(armcal.ArmcalError) as e:
        armcal.Cell.load(str(path))
    assert "bad-cell.toml" in str(e.value) and "bogus_field" in str(e.value)
    with pytest.raises(armcal.ArmcalError):
        armcal.Cell.load(str(tmp_path / "missing.toml"))


def test_parameters(cell):
    params = cell.parameters()
    assert len(params) == len(cell.nominal())
    assert sum(p["status"] != "fixed" for p in params) == 27  # the paper cell's free set
    assert {p["status"] for p in params} <= {"free", "fixed", "prior"}
    for p, nominal in zip(params, cell.nominal()):
        assert p["nominal"] == nominal
        if p["unit"] == "deg":
            assert p["nominal_display"] == pytest.approx(np.degrees(nominal), abs=1e-12)
        if p["reason"] is not None:
            assert p["status"] == "fixed"


def test_every_record_pickles(cell, fitted, tmp_path):
    q, data, est = fitted
    design = armcal.plan(cell, 10, collisions=False)
    state = armcal.campaign_start(cell, batch=4)
    drift = armcal.check(cell, est, data)
    for record in (data, est, design, state, drift):
        back = pickle.loads(pickle.dumps(record))
        assert type(back) is type(record)
        assert back.to_json() == record.to_json()
    back = pickle.loads(pickle.dumps(cell))
    np.testing.assert_array_equal(back.nominal(), cell.nominal())
    toml_cell = armcal.Cell.from_toml(PAPER_CELL.read_text())
    assert pickle.loads(pickle.dumps(toml_cell)).name == toml_cell.name
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(est)).params, est.params)


def test_identify_recovers_the_truth(cell, fitted):
    """Against the known truth of the simulation: every free parameter within 5σ."""
    q, data, est = fitted
    truth = armcal.perturbed_truth(cell, seed=7)
    index = {n: i for i, n in enumerate(est.names)}
    free = [index[n] for n in est.free]
    z = (est.params[free] - truth[free]) / est.sigma
    assert est.converged and np.all(np.abs(z) < 5), z


def test_gil_released_during_identify(cell):
    """A second Python thread keeps counting while identify runs."""
    q = np.radians(random_poses_deg(cell, 1000, 9))
    data = armcal.simulate(cell, q, truth=armcal.perturbed_truth(cell, seed=2), seed=3)
    ticks = []
    stop = threading.Event()

    def counter():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    result = {}
    worker = threading.Thread(target=lambda: result.setdefault("est", armcal.identify(cell, data)))
    t = threading.Thread(target=counter)
    t.start()
    time.sleep(0.02)
    start = time.perf_counter()
    worker.start()
    worker.join()
    end = time.perf_counter()
    stop.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    assert result["est"].converged
    # With the GIL held the counter would not tick at all during the call.
    assert end - start > 0.01 and len(during) >= 3, (end - start, len(during))


def test_progress_callback(cell, fitted):
    q, data, _ = fitted
    events = []
    armcal.identify(cell, data, progress=lambda e, info: events.append((e, info)))
    kinds = [e for e, _ in events]
    assert "iteration" in kinds
    it = next(info for e, info in events if e == "iteration")
    assert set(it) == {"iteration", "cost", "damping"}

    def broken(event, info):
        raise KeyError("from the callback")

    with pytest.raises(KeyError, match="from the callback"):
        armcal.identify(cell, data, progress=broken)


def test_sigma_weights_rows_of_a_per_measurement_cell(cell, fitted):
    q, data, est = fitted
    # The paper cell's noise model is constant: row σ would not be used, which is an error.
    with pytest.raises(armcal.ArmcalError, match="sigma: .*noise model is constant"):
        armcal.identify(cell, q, data.measured, sigma=0.1)
    text = PAPER_CELL.read_text().replace(
        'noise = { model = "constant", sigma_mm = 1.0 }',
        'noise = { model = "per-measurement", floor_mm = 0.001 }')
    per_row = armcal.Cell.from_toml(text)
    one = armcal.identify(per_row, q, data.measured, sigma=0.1)
    two = armcal.identify(per_row, q, data.measured, sigma=[0.2, 0.2, 0.2])
    np.testing.assert_allclose(two.params, one.params, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(two.sigma, 2 * one.sigma, rtol=1e-6)
    with pytest.raises(armcal.ArmcalError, match="sigma: row 1"):
        armcal.identify(per_row, q, data.measured, sigma=-1.0)


def test_campaign_until_target(cell):
    truth = armcal.perturbed_truth(cell, seed=4)
    state = armcal.campaign_start(cell, target_sigma_mm=0.3, batch=10, budget=60, seed=2)
    estimate = None
    for step in range(8):
        if not state.next_ids:
            break
        q = state.next_q(cell)
        assert q.shape == (len(state.next_ids), cell.dof)
        batch = armcal.simulate(cell, q, truth=truth, seed=100 + step, ids=state.next_ids)
        state, estimate = armcal.campaign_step(cell, state, batch)
    assert state.decision.startswith("stop"), state.decision
    assert estimate is not None and estimate.converged
    assert state.measured <= 60


def test_compensate_targets(cell, fitted):
    q, _, est = fitted
    # Targets: the nominal tool poses of q, solved on the calibrated robot from q.
    targets = armcal.fk(cell, q[:5])
    out = armcal.compensate(cell, est, q[:5], targets=targets)
    assert all(s == "converged" for s in out["status"])
    reached = armcal.fk(cell, out["q"], params=est)
    np.testing.assert_allclose(reached[:, :3, 3], targets[:, :3, 3], atol=1e-6)


def test_report(cell, fitted, tmp_path):
    _, _, est = fitted
    design = armcal.plan(cell, 10, collisions=False)
    path = armcal.report([design, est], str(tmp_path / "rep"), title="From Python")
    html = open(path).read()
    assert path.endswith("report.html") and "From Python" in html and "<svg" in html
    with pytest.raises(armcal.ArmcalError, match=r"records\[0\]"):
        armcal.report([3], str(tmp_path / "x.html"))
    assert not (tmp_path / "x.html").exists()
