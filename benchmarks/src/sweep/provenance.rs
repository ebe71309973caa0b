//! `provenance.json`: what produced a sweep folder (software version and
//! commit, main dependency versions, CPU, threads, start time), so figures
//! can be compared across machines and builds.

use serde_json::{Map, Value, json};

pub const PROVENANCE_JSON: &str = "provenance.json";

/// The record of a run started now, as `shard` (`K/N`).
pub fn record(shard: &str) -> Value {
    let crates: Map<String, Value> = env!("SFP_DEP_VERSIONS")
        .split(',')
        .filter_map(|nv| nv.split_once('='))
        .map(|(n, v)| (n.to_string(), Value::from(v)))
        .collect();
    json!({
        "version": env!("CARGO_PKG_VERSION"),
        "commit": sfp_core::COMMIT,
        "crates": crates,
        "cpu": cpu_model(),
        "threads": rayon::current_num_threads(),
        "started": sfp_core::provenance::now(),
        "shard": shard,
    })
}

/// The first `model name` of `/proc/cpuinfo`, or `unknown`.
fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}

#[cfg(test)]
mod tests {
    #[test]
    fn record_has_the_fields() {
        let r = super::record("1/1");
        for key in ["version", "commit", "crates", "cpu", "threads", "started"] {
            assert!(!r[key].is_null(), "{key}");
        }
        assert!(r["crates"]["rayon"].is_string(), "{r}");
        let started = r["started"].as_str().unwrap();
        assert_eq!(started.len(), 20, "{started}");
        assert!(started.starts_with("20"), "{started}");
    }
}
