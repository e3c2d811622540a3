"""armcal from Python: kinematic calibration of industrial robots, numpy in, numpy out.

Units are armcal's internal ones: joint values in radians (mm for a prismatic joint),
lengths in mm, angles in radians. Records (``Estimate``, ``Design``, ``Dataset``,
``CampaignState``, ``DriftCheck``) pickle through their JSON; ``to_json()`` gives what the
``armcal`` command line writes. Errors are raised as ``ArmcalError`` (a ``ValueError``)
with armcal's message, which names the file, line or row, and field.

The user guide's page "armcal from Python" (docs/src/python.md) walks through it.
"""

from ._armcal import (
    ArmcalError,
    CampaignState,
    Cell,
    Dataset,
    Design,
    DriftCheck,
    Estimate,
    __version__,
    assess,
    campaign_start,
    campaign_step,
    check,
    compensate,
    dataset,
    fk,
    fleet,
    fleet_task,
    identify,
    perturbed_truth,
    plan,
    predict,
    read_record,
    report,
    simulate,
)

__all__ = [
    "ArmcalError",
    "CampaignState",
    "Cell",
    "Dataset",
    "Design",
    "DriftCheck",
    "Estimate",
    "__version__",
    "assess",
    "campaign_start",
    "campaign_step",
    "check",
    "compensate",
    "dataset",
    "fk",
    "fleet",
    "fleet_task",
    "identify",
    "perturbed_truth",
    "plan",
    "predict",
    "read_record",
    "report",
    "simulate",
]
