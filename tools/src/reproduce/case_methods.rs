//! A case's methods as the claims' checks see them: each label's plugin kind, whether the
//! scenario has references, what a computed case records, which methods write each image map.

use std::collections::BTreeMap;

use crate::suite::metric::Metric;

/// A case's method labels and the plugin kind of each, read from its scenario.
#[derive(Clone, Debug)]
pub struct CaseMethods {
    pub kinds: BTreeMap<String, &'static str>,
    /// The scenario has reference frames (FLIP, MSE, PSNR are measured).
    pub references: bool,
    /// A computed case: the metrics each method records.
    pub computed: Option<BTreeMap<String, Vec<Metric>>>,
    /// Per image map a registered statistic reads (`FolderInput::EventAndMap`), the labels of
    /// the methods that write it (NIRC's blends and switch write `preference`).
    pub image_maps: BTreeMap<&'static str, Vec<String>>,
}
