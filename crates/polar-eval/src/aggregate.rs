//! Aggregation of per-sample task metrics (JSON objects) into per-family, per-task means:
//! every numeric leaf is averaged over the samples that have it, so a new metric field is
//! aggregated without code here.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

/// The mean of each numeric leaf over the samples of one family and task.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Aggregate {
    /// Samples whose task succeeded.
    pub samples: usize,
    /// Samples whose task failed or could not run.
    pub failed: usize,
    /// Mean seconds of the task per megapixel.
    pub seconds_per_mp: Option<f64>,
    /// Mean of each numeric leaf of the metrics, keyed by its dotted path
    /// (e.g. `normal.mean_deg`); list entries are keyed by index.
    pub means: BTreeMap<String, f64>,
}

/// One task's result for one sample, as `polar-vision run` writes it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// `true` when the task ran.
    pub ok: bool,
    /// Why it did not, or warnings.
    pub messages: Vec<String>,
    /// Wall time of the task, seconds.
    pub seconds: f64,
    /// Megapixels of the input.
    pub megapixels: f64,
    /// The task's metrics (absent without ground truth).
    pub metrics: Option<Value>,
}

/// The family of a sample folder name: the name without a trailing `-<digits>`
/// (`sfp-00012` -> `sfp`); the whole name where there is none.
pub fn family_of(sample: &str) -> &str {
    match sample.rsplit_once('-') {
        Some((head, tail)) if !tail.is_empty() && tail.bytes().all(|b| b.is_ascii_digit()) => head,
        _ => sample,
    }
}

/// Per family, per task: the aggregate of `samples` (sample name -> task name -> summary).
pub fn aggregate(
    samples: &BTreeMap<String, BTreeMap<String, Summary>>,
) -> BTreeMap<String, BTreeMap<String, Aggregate>> {
    let mut sums: BTreeMap<(String, String), Accumulator> = BTreeMap::new();
    for (name, tasks) in samples {
        for (task, s) in tasks {
            sums.entry((family_of(name).to_owned(), task.clone()))
                .or_default()
                .add(s);
        }
    }
    let mut out: BTreeMap<String, BTreeMap<String, Aggregate>> = BTreeMap::new();
    for ((family, task), acc) in sums {
        out.entry(family).or_default().insert(task, acc.finish());
    }
    out
}

#[derive(Default)]
struct Accumulator {
    ok: usize,
    failed: usize,
    time: (f64, usize),
    leaves: BTreeMap<String, (f64, usize)>,
}

impl Accumulator {
    fn add(&mut self, s: &Summary) {
        if !s.ok {
            self.failed += 1;
            return;
        }
        self.ok += 1;
        if s.megapixels > 0.0 {
            self.time.0 += s.seconds / s.megapixels;
            self.time.1 += 1;
        }
        if let Some(m) = &s.metrics {
            add_leaves(&mut self.leaves, String::new(), m);
        }
    }

    fn finish(self) -> Aggregate {
        let mean = |(sum, n): (f64, usize)| (n > 0).then(|| sum / n as f64);
        Aggregate {
            samples: self.ok,
            failed: self.failed,
            seconds_per_mp: mean(self.time),
            means: self
                .leaves
                .into_iter()
                .filter_map(|(k, v)| mean(v).map(|m| (k, m)))
                .collect(),
        }
    }
}

/// Adds every finite number under `v` to `leaves`, keyed by its dotted path.
fn add_leaves(leaves: &mut BTreeMap<String, (f64, usize)>, path: String, v: &Value) {
    let join = |k: &str| {
        if path.is_empty() {
            k.to_owned()
        } else {
            format!("{path}.{k}")
        }
    };
    match v {
        Value::Number(n) => {
            if let Some(x) = n.as_f64().filter(|x| x.is_finite()) {
                let e = leaves.entry(path).or_insert((0.0, 0));
                e.0 += x;
                e.1 += 1;
            }
        }
        Value::Object(map) => map_leaves(leaves, map, join),
        Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                add_leaves(leaves, join(&i.to_string()), item);
            }
        }
        _ => {}
    }
}

fn map_leaves(
    leaves: &mut BTreeMap<String, (f64, usize)>,
    map: &Map<String, Value>,
    join: impl Fn(&str) -> String,
) {
    for (k, v) in map {
        add_leaves(leaves, join(k), v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn ok(metrics: Value) -> Summary {
        Summary {
            ok: true,
            messages: vec![],
            seconds: 0.5,
            megapixels: 0.25,
            metrics: Some(metrics),
        }
    }

    #[test]
    fn families_come_from_the_folder_name() {
        assert_eq!(family_of("sfp-00012"), "sfp");
        assert_eq!(family_of("my-glass-3"), "my-glass");
        assert_eq!(family_of("frame"), "frame");
        assert_eq!(family_of("frame-a1"), "frame-a1");
    }

    #[test]
    fn numeric_leaves_are_averaged_and_failures_counted() {
        let mut samples = BTreeMap::new();
        let failed = Summary {
            ok: false,
            messages: vec!["no haze".into()],
            seconds: 0.0,
            megapixels: 0.25,
            metrics: None,
        };
        samples.insert(
            "sfp-00000".to_owned(),
            BTreeMap::from([(
                "sfp".to_owned(),
                ok(json!({"a": 1.0, "b": {"c": [2.0, null]}})),
            )]),
        );
        samples.insert(
            "sfp-00001".to_owned(),
            BTreeMap::from([
                (
                    "sfp".to_owned(),
                    ok(json!({"a": 3.0, "b": {"c": [4.0, 5.0]}})),
                ),
                ("dehaze".to_owned(), failed),
            ]),
        );
        let agg = aggregate(&samples);
        let sfp = &agg["sfp"]["sfp"];
        assert_eq!((sfp.samples, sfp.failed), (2, 0));
        assert_eq!(sfp.means["a"], 2.0);
        assert_eq!(sfp.means["b.c.0"], 3.0);
        assert_eq!(sfp.means["b.c.1"], 5.0);
        assert_eq!(sfp.seconds_per_mp, Some(2.0));
        assert_eq!(agg["sfp"]["dehaze"].failed, 1);
    }
}
