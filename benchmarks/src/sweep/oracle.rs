//! A sweep's oracle entries (`[[methods]] oracle = "mixed"`): the
//! per-pixel bound beside the methods, scored on each exposure
//! (`sfp_core::oracle::oracles_of`) at the view's true η.

use sfp_core::oracle::OracleModel;

/// A per-pixel oracle beside the methods (`sfp_core::oracle`): each
/// exposure's best per-pixel reading under a reflection model, picked with
/// the ground truth at the view's true η. No per-pixel method can beat it;
/// a surface fit can, so a sweep's paired comparisons give a method's
/// distance to it with an interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Oracle {
    pub model: OracleModel,
    /// The view's true η: `None` in the file's entry, the view's in a
    /// planned row.
    pub eta: Option<f64>,
}

/// An oracle's entry (`oracle = "diffuse"` or `"mixed"`, optionally
/// `label`): its label (by default `oracle-MODEL`) and the oracle, or the
/// key at fault and why.
pub fn parse(table: &toml::Table) -> std::result::Result<(String, Oracle), (String, String)> {
    if let Some(key) = table
        .keys()
        .find(|k| !["oracle", "label"].contains(&k.as_str()))
    {
        return Err((
            key.clone(),
            "an oracle takes no options (only `oracle` and `label`)".into(),
        ));
    }
    let named = table.get("oracle").and_then(|v| v.as_str());
    let Some(model) = OracleModel::ALL
        .into_iter()
        .find(|m| Some(m.name()) == named)
    else {
        return Err((
            "oracle".into(),
            format!(
                "{} is not an oracle: \"diffuse\" or \"mixed\"",
                table
                    .get("oracle")
                    .map_or("nothing".to_string(), |v| v.to_string())
            ),
        ));
    };
    let label = match table.get("label") {
        Some(toml::Value::String(label)) => label.clone(),
        None => format!("oracle-{}", model.name()),
        Some(other) => return Err(("label".into(), format!("must be text, not {other}"))),
    };
    Ok((label, Oracle { model, eta: None }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> toml::Table {
        text.parse().unwrap()
    }

    #[test]
    fn an_oracle_entry_reads_its_model_and_refuses_options() {
        let (label, o) = parse(&table("oracle = \"mixed\"")).unwrap();
        assert_eq!(
            (label.as_str(), o.model, o.eta),
            ("oracle-mixed", OracleModel::Mixed, None)
        );
        let (label, o) = parse(&table("oracle = \"diffuse\"\nlabel = \"bound\"")).unwrap();
        assert_eq!((label.as_str(), o.model), ("bound", OracleModel::Diffuse));
        let (key, why) = parse(&table("oracle = \"mixed\"\nlambda = 1.0")).unwrap_err();
        assert!(key == "lambda" && why.contains("takes no options"), "{why}");
        let (key, why) = parse(&table("oracle = \"specular\"")).unwrap_err();
        assert!(
            key == "oracle" && why.contains("\"diffuse\" or \"mixed\""),
            "{why}"
        );
    }
}
