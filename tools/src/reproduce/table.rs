//! Each played case's table: every method of the case against every statistic its claims
//! read, the mean over seeds with its 95% interval (the numbers the claims are judged on, for
//! all methods, as the paper's tables list them), and the case's own `table` columns.

use super::verdict::interval;

pub struct CaseTable {
    pub case: String,
    pub seeds: usize,
    /// `metric window` per column.
    pub columns: Vec<String>,
    /// Per method: one cell per column.
    pub rows: Vec<(String, Vec<String>)>,
}

/// `mean [lo, hi]`, or why there is no number.
pub(crate) fn cell(values: Result<Vec<f64>, String>) -> String {
    match values {
        Ok(v) if v.len() >= 2 => {
            let (mean, half) = interval(&v, 0.95);
            format!("{mean:.4} [{:.4}, {:.4}]", mean - half, mean + half)
        }
        Ok(v) => v.first().map_or("-".into(), |x| format!("{x:.4}")),
        Err(_) => "-".into(),
    }
}

/// A table as Markdown.
pub fn markdown(t: &CaseTable) -> String {
    let mut md = format!(
        "\n### Case {} (mean [95% interval] over {} seeds)\n\n| method | {} |\n|---|{}\n",
        t.case,
        t.seeds,
        t.columns.join(" | "),
        "---|".repeat(t.columns.len())
    );
    for (m, cells) in &t.rows {
        md.push_str(&format!("| {m} | {} |\n", cells.join(" | ")));
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_hold_the_mean_and_its_interval() {
        // Mean 2.0, standard error 0.0058, t(0.975, 2) = 4.303: half-width 0.0248.
        assert_eq!(cell(Ok(vec![1.99, 2.0, 2.01])), "2.0000 [1.9752, 2.0248]");
        assert_eq!(cell(Ok(vec![0.5])), "0.5000");
        assert_eq!(cell(Err("no values".into())), "-");
    }
}
