//! The method labels of a sweep, in the order the report lists them, with
//! what their configuration says: which registered method, and which of its
//! steps are switched off (an ablation). Names, display names and ablation
//! switches come from the methods' declarations (`sfp_reconstruct::method`).

use crate::row::Row;
use serde::Serialize;
use sfp_reconstruct::method::About;
use sfp_reconstruct::methods::{ABOUT, METHODS};

/// One method label of a sweep.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MethodInfo {
    /// The label rows carry (`Row::method`).
    pub label: String,
    /// Registered method of its configuration (`smsfp`, `smith`, …; `?`
    /// when the configuration names none, as a command method's).
    pub method: String,
    /// The method's ablation switches (options) this label turns off.
    pub ablated: Vec<String>,
}

impl MethodInfo {
    fn of(row: &Row) -> MethodInfo {
        let method = row.config["method"].as_str().unwrap_or("?").to_string();
        let ablated = about(&method)
            .map(|about| {
                about
                    .ablations
                    .iter()
                    .filter(|a| row.config.get(a.option).is_some_and(|v| a.is_off(v)))
                    .map(|a| a.option.to_string())
                    .collect()
            })
            .unwrap_or_default();
        MethodInfo {
            label: row.method.clone(),
            method,
            ablated,
        }
    }

    pub fn is_ablation(&self) -> bool {
        !self.ablated.is_empty()
    }

    /// Readable name: the method's display name for a label that is just
    /// the method (`smsfp` → `SMSfP`), the label otherwise.
    pub fn display(&self) -> String {
        match about(&self.method) {
            Some(about) if self.label == self.method => about.display.to_string(),
            _ => self.label.clone(),
        }
    }

    /// `w/o PARG, MFCP` for an ablation, empty otherwise.
    pub fn ablation_text(&self) -> String {
        let Some(about) = about(&self.method).filter(|_| self.is_ablation()) else {
            return String::new();
        };
        let steps: Vec<&str> = about
            .ablations
            .iter()
            .filter(|a| self.ablated.iter().any(|o| o == a.option))
            .map(|a| a.step)
            .collect();
        format!("w/o {}", steps.join(", "))
    }
}

/// The declaration of the registered method `name`.
fn about(name: &str) -> Option<&'static About> {
    ABOUT.iter().find(|a| a.name == name)
}

/// Every label of `rows` (first configuration seen for each), ordered by
/// registered method as in the paper's tables (Atkinson, Mahmoud, Smith,
/// SMSfP, then unknown methods), full methods before ablations, then by
/// label: the order does not depend on the order of the rows.
pub fn catalog(rows: &[Row]) -> Vec<MethodInfo> {
    let mut infos: Vec<MethodInfo> = Vec::new();
    for r in rows {
        if !infos.iter().any(|i| i.label == r.method) {
            infos.push(MethodInfo::of(r));
        }
    }
    let rank = |m: &MethodInfo| {
        METHODS
            .iter()
            .position(|&n| n == m.method)
            .unwrap_or(METHODS.len())
    };
    infos.sort_by(|a, b| {
        (rank(a), a.is_ablation(), &a.label).cmp(&(rank(b), b.is_ablation(), &b.label))
    });
    infos
}

/// The label SMSfP is compared from: `smsfp` if present, else the first
/// full (not ablated) SMSfP label.
pub fn reference(catalog: &[MethodInfo]) -> Option<&MethodInfo> {
    catalog
        .iter()
        .find(|m| m.label == "smsfp" && m.method == "smsfp")
        .or_else(|| {
            catalog
                .iter()
                .find(|m| m.method == "smsfp" && !m.is_ablation())
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(label: &str, config: serde_json::Value) -> Row {
        Row {
            key: label.into(),
            dataset: "d".into(),
            view: "v".into(),
            object: "o".into(),
            axes: Default::default(),
            method: label.into(),
            config,
            seed: 0,
            metrics: None,
            error: None,
            view_dir: String::new(),
            pictures: None,
            estimates: None,
            exit_status: None,
            stderr_tail: None,
        }
    }

    #[test]
    fn labels_sort_like_the_paper_and_ablations_are_recognised() {
        use serde_json::json;
        let rows = vec![
            row("smsfp-no-parg", json!({"method": "smsfp", "parg": false})),
            row("smsfp", json!({"method": "smsfp", "parg": true})),
            row("smith", json!({"method": "smith"})),
            row("atkinson", json!({"method": "atkinson"})),
            row("x", json!({})),
            row("mine", json!({"command": ["predict"], "axes": "ours"})),
        ];
        let c = catalog(&rows);
        let labels: Vec<&str> = c.iter().map(|m| m.label.as_str()).collect();
        assert_eq!(
            labels,
            ["atkinson", "smith", "smsfp", "smsfp-no-parg", "mine", "x"]
        );
        // A command method is known by its name alone.
        assert_eq!(
            (c[4].display(), c[4].ablation_text()),
            ("mine".into(), String::new())
        );
        assert_eq!(c[3].ablated, ["parg"]);
        assert_eq!(c[3].ablation_text(), "w/o PARG");
        assert_eq!(c[2].display(), "SMSfP");
        let several = catalog(&[row(
            "bare",
            json!({"method": "smsfp", "mfcp": false, "shading_sense": 0.0, "parg": false}),
        )]);
        assert_eq!(several[0].ablation_text(), "w/o PARG, MFCP, shading sense");
        assert_eq!(reference(&c).unwrap().label, "smsfp");
    }
}
