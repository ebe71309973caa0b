//! `provenance.json`: what produced a sweep folder (software version and
//! commit, main dependency versions, CPU, threads, start time), so figures
//! can be compared across machines and builds.

use serde_json::{Map, Value, json};
use std::time::{SystemTime, UNIX_EPOCH};

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
        "commit": env!("SFP_GIT_COMMIT"),
        "crates": crates,
        "cpu": cpu_model(),
        "threads": rayon::current_num_threads(),
        "started": utc_now(),
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

/// The current time as `YYYY-MM-DDTHH:MM:SSZ`.
fn utc_now() -> String {
    let secs = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (days, rem) = (secs / 86_400, secs % 86_400);
    // Civil date from days since 1970-01-01 (Howard Hinnant's algorithm).
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
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
