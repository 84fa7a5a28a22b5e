//! The figures the issues ask of `focal bench` (issue 24's table, issue 23's streaming
//! goals): each a largest ratio for one configuration of one group against that group's
//! baseline. The bench prints each beside its row, marks the rows that miss it and ends
//! with a count; `--json` carries them as `goal` and `goal_met`.

/// A row's goal: its ratio at most `ratio` (`why` says what the ratio stands for where
/// it is not plain "at most this much slower").
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Goal {
    pub(super) ratio: f64,
    pub(super) why: &'static str,
}

/// (group, configuration, largest ratio, what it stands for).
const GOALS: &[(&str, &str, f64, &str)] = &[
    ("lenses", "magnifier + AA", 1.3, "the paper's anti-aliased lenses: 8–28 % slower"),
    ("lenses", "feature (GPU)", 1.25, "its silhouette found every frame"),
    ("context", "context κt 0", 1.05, "DVR's cost where equation 5 changes nothing"),
    ("twolevel", "two-level, dvr + mip + xray", 1.3, ""),
    ("windows", "one clip window, same look", 1.05, ""),
    ("windows", "four clip windows, same look", 1.15, ""),
    ("explode", "64 parts, at rest", 1.10, ""),
    ("explode", "64 parts, exploded", 1.25, "80 % of the plain frame rate"),
    ("bricked", "orbit, resident", 2.0, ""),
    ("bricked", "magnifier 4×", 1.3, ""),
    ("bricked", "first frame 8192³", 1.0, "under 1 s"),
    ("bricked", "rss 1024³ default", 1.0, "under 1 GiB"),
    ("bricked", "rss 1024³, 200 MiB cache", 1.0, "within the 200 MiB cache"),
];

/// The goal of `config` in `group`, if the issues set one.
pub(super) fn of(group: &str, config: &str) -> Option<Goal> {
    GOALS.iter().find(|(g, c, _, _)| *g == group && *c == config).map(|&(_, _, ratio, why)| Goal { ratio, why })
}

impl Goal {
    /// Whether `ratio` meets the goal (a ratio that is not a number does not).
    pub(super) fn met(&self, ratio: f64) -> bool {
        ratio <= self.ratio
    }

    /// "goal ≤ ×1.30 met" or "goal ≤ ×1.30 MISSED", with what it stands for.
    pub(super) fn verdict(&self, ratio: f64) -> String {
        let why = if self.why.is_empty() { String::new() } else { format!(", {}", self.why) };
        format!("goal ≤ ×{:.2}{why}: {}", self.ratio, if self.met(ratio) { "met" } else { "MISSED" })
    }
}

/// The closing line: how many of the run's goals were met, and which were missed.
pub(super) fn summary<'a>(rows: impl Iterator<Item = (&'a str, &'a str, f64)>) -> Option<String> {
    let (mut met, mut missed) = (0, Vec::new());
    for (group, config, ratio) in rows {
        match of(group, config) {
            Some(goal) if goal.met(ratio) => met += 1,
            Some(goal) => missed.push(format!("{group} / {config} ×{ratio:.2} (goal ≤ ×{:.2})", goal.ratio)),
            None => {}
        }
    }
    (met + missed.len() > 0).then(|| {
        let list = if missed.is_empty() { String::new() } else { format!(": {}", missed.join("; ")) };
        format!("goals: {met} met, {} missed{list}", missed.len())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_meets_its_goal_at_or_under_the_ratio_and_nan_misses() {
        let magnifier = of("lenses", "magnifier + AA").unwrap();
        assert!(magnifier.met(1.3) && magnifier.met(0.9) && !magnifier.met(1.31) && !magnifier.met(f64::NAN));
        assert_eq!(magnifier.verdict(1.64), "goal ≤ ×1.30, the paper's anti-aliased lenses: 8–28 % slower: MISSED");
        assert_eq!(of("windows", "one clip window, same look").unwrap().verdict(1.02), "goal ≤ ×1.05: met");
        // 80 % of the plain frame rate is a ratio of 1.25.
        assert_eq!(of("explode", "64 parts, exploded").map(|g| g.ratio), Some(1.25));
        assert_eq!(of("explode", "2 parts, exploded"), None);
        assert_eq!(of("lenses", "magnifier"), None);
    }

    #[test]
    fn the_summary_counts_the_goals_of_the_rows_run() {
        let rows = [("lenses", "no lens", 1.0), ("lenses", "magnifier + AA", 1.64), ("context", "context κt 0", 0.98)];
        assert_eq!(summary(rows.into_iter()).as_deref(), Some("goals: 1 met, 1 missed: lenses / magnifier + AA ×1.64 (goal ≤ ×1.30)"));
        assert_eq!(summary([("modes", "mip", 0.5)].into_iter()), None);
    }
}
