//! The inputs of a report: armcal's JSON files, recognised by their content — an estimate
//! (`armcal identify`, `armcal demo`), a design (`armcal plan`, `armcal demo`), a study
//! (`armcal study paper`), the demo's summary or a simulation's truth record (`armcal
//! simulate`'s truth file), a campaign's state (`armcal campaign`) or a drift check
//! (`armcal check`).

use crate::campaign::drift::DriftCheck;
use crate::campaign::CampaignState;
use crate::design::DesignRecord;
use crate::identify::tree::TreeEstimate;
use crate::identify::Estimate;
use crate::sim::TruthRecord;
use crate::study::demo::DemoSummary;
use crate::study::paper::StudyRecord;
use crate::Error;
use std::path::Path;

/// One input of a report.
#[derive(Clone, Debug)]
pub enum Document {
    /// An identification result (`armcal identify`, `armcal demo`).
    Estimate(Box<Estimate>),
    /// A design record (the .json `armcal plan` writes beside the design CSV).
    Design(Box<DesignRecord>),
    /// The result of `armcal study paper`.
    Study(StudyRecord),
    /// The `summary.json` of `armcal demo`.
    Demo(Box<DemoSummary>),
    /// The true parameters of a simulation: estimates of its cell are compared with them.
    Truth(TruthRecord),
    /// The state of an adaptive campaign (`campaign.json` of `armcal campaign`).
    Campaign(Box<CampaignState>),
    /// A drift check (`check.json` of `armcal check`).
    Check(Box<DriftCheck>),
    /// The estimate of a kinematic tree (`armcal identify` of a tree cell).
    TreeEstimate(Box<TreeEstimate>),
}

const EXPECTED: &str = "expected an armcal estimate (from `armcal identify`), design (the .json \
    `armcal plan` writes beside the design CSV), study result (`armcal study paper`), demo \
    summary (`armcal demo`), truth record (the truth file of `armcal simulate`), campaign \
    state (the campaign.json of `armcal campaign`) or drift check (`armcal check`)";

impl Document {
    /// Recognises and reads an armcal JSON document; `file` names it in errors.
    pub fn from_json(text: &str, file: &str) -> Result<Document, Error> {
        let fail = |message: String| Error::File {
            file: file.into(),
            message,
        };
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| fail(format!("not JSON ({e}); {EXPECTED}")))?;
        let obj = value
            .as_object()
            .ok_or_else(|| fail(format!("not a JSON object; {EXPECTED}")))?;
        let has = |keys: &[&str]| keys.iter().all(|k| obj.contains_key(*k));
        let read = |what: &str| {
            let what = what.to_string();
            move |e: serde_json::Error| fail(format!("looks like an armcal {what}, but: {e}"))
        };
        if obj.get("kind").and_then(|k| k.as_str()) == Some("tree-estimate") {
            return Ok(Document::TreeEstimate(Box::new(
                serde_json::from_value(value).map_err(read("tree estimate"))?,
            )));
        }
        if let Some(study) = obj.get("study") {
            return match study.as_str() {
                Some("paper") => Ok(Document::Study(
                    serde_json::from_value(value).map_err(read("study result"))?,
                )),
                other => Err(fail(format!(
                    "a study result of `{}`; the report covers `armcal study paper` results ({EXPECTED})",
                    other.unwrap_or("?")
                ))),
            };
        }
        if obj.get("campaign").and_then(|c| c.as_str()) == Some("adaptive") {
            return Ok(Document::Campaign(Box::new(
                serde_json::from_value(value).map_err(read("campaign state"))?,
            )));
        }
        if has(&["calibrated_on", "chi2", "p_value", "groups"]) {
            return Ok(Document::Check(Box::new(
                serde_json::from_value(value).map_err(read("drift check"))?,
            )));
        }
        if has(&["parameters", "solver", "uncertainty", "model"]) {
            return Ok(Document::Estimate(Box::new(
                serde_json::from_value(value).map_err(read("estimate"))?,
            )));
        }
        if has(&["assessment", "poses", "joints"]) {
            return Ok(Document::Design(Box::new(
                serde_json::from_value(value).map_err(read("design"))?,
            )));
        }
        if has(&[
            "nominal_held_out",
            "heuristic",
            "kpi",
            "program_miss_nominal",
        ]) {
            return Ok(Document::Demo(Box::new(
                serde_json::from_value(value).map_err(read("demo summary"))?,
            )));
        }
        let is_truth = obj
            .get("parameters")
            .and_then(|p| p.as_array())
            .and_then(|p| p.first())
            .is_some_and(|p| p.get("truth").is_some());
        if has(&["cell", "seed", "parameters"]) && is_truth {
            return Ok(Document::Truth(
                serde_json::from_value(value).map_err(read("truth record"))?,
            ));
        }
        let keys: Vec<&str> = obj.keys().map(String::as_str).take(8).collect();
        Err(fail(format!(
            "not an armcal result (top-level fields: {}); {EXPECTED}",
            if keys.is_empty() {
                "none".to_string()
            } else {
                keys.join(", ")
            }
        )))
    }

    /// Reads a file.
    pub fn from_file(path: &Path) -> Result<Document, Error> {
        let text =
            crate::input::read_capped(path, crate::input::TEXT_CAP).map_err(|e| Error::File {
                file: path.display().to_string(),
                message: e.to_string(),
            })?;
        Document::from_json(&text, &path.display().to_string())
    }

    /// What kind of document this is, for messages and headings.
    pub fn kind(&self) -> &'static str {
        match self {
            Document::Estimate(_) => "estimate",
            Document::Design(_) => "design",
            Document::Study(_) => "study",
            Document::Demo(_) => "demo summary",
            Document::Truth(_) => "truth",
            Document::Campaign(_) => "campaign",
            Document::Check(_) => "drift check",
            Document::TreeEstimate(_) => "tree estimate",
        }
    }
}
