//! The data-quality stage's end ([`DataQualityStage`]): its rows are the log's, before the
//! chain (`monitor_io::log::quality`, run by `diagnose`); at the end it gives the
//! data-quality finding, and whether the data can carry a verdict at all.

use crate::stage::Finish;
use crate::verdict::measured::data_quality_finding;
use crate::verdict::FindingReport;
use monitor_core::SensorFlags;
use monitor_io::log::quality::{DataQuality, MAX_NOT_JUDGED_FRACTION};

/// The data-quality stage at its end: what it found in the log and did about it.
#[derive(Debug, Clone)]
pub(crate) struct DataQualityStage {
    quality: DataQuality,
}

/// What the data-quality stage found.
#[derive(Debug, Clone)]
pub(crate) struct QualityFinding {
    /// The report's `data_quality`.
    pub(crate) quality: DataQuality,
    /// The data-quality finding (the core's sensor flags at the end among it).
    pub(crate) finding: FindingReport,
    /// Why the data cannot carry a verdict, where they cannot: the stage does not trust
    /// them, or more of the log could not be judged than a verdict allows
    /// ([`MAX_NOT_JUDGED_FRACTION`]). Every fault-judging finding is then not judged.
    pub(crate) distrusts: Option<crate::verdict::Detail>,
}

impl DataQualityStage {
    /// The stage's end with its report `quality`.
    pub(crate) fn new(quality: DataQuality) -> Self {
        DataQualityStage { quality }
    }
}

impl Finish for DataQualityStage {
    /// The core's sensor flags at the end of the replay.
    type Closing<'a> = SensorFlags;
    type Finding = QualityFinding;

    fn finish(self, sensors: SensorFlags) -> QualityFinding {
        let finding = data_quality_finding(&self.quality, sensors);
        let distrusts =
            (!self.quality.trusted || unjudged(&self.quality)).then(|| finding.detail.clone());
        QualityFinding {
            quality: self.quality,
            finding,
            distrusts,
        }
    }
}

/// More of the log could not be judged than a verdict allows
/// ([`MAX_NOT_JUDGED_FRACTION`]).
fn unjudged(q: &DataQuality) -> bool {
    let unjudged: f64 = q.not_judged.iter().map(|n| n.to_s - n.from_s).sum();
    unjudged > MAX_NOT_JUDGED_FRACTION * q.duration_s.max(f64::MIN_POSITIVE)
}
