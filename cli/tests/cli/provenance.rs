//! `sfp eval` and a result whose `run.json` cannot say which view it came
//! from: refused when the record is a folder or records no view, scored
//! with a warning when there is none (another tool's normals). Before, all
//! three were scored silently.

use crate::common::*;

#[test]
fn eval_refuses_a_result_whose_view_cannot_be_read() {
    let dir = tempfile::tempdir().unwrap();
    let view = small_view(dir.path());
    let v = view.as_str();
    let result = dir.path().join("result");
    let r = result.to_str().unwrap();
    assert!(sfp(&["reconstruct", v, "--out", r]).status.success());
    let run = result.join("run.json");
    let record = std::fs::read_to_string(&run).unwrap();
    // A record without its view entry.
    let mut value: serde_json::Value = serde_json::from_str(&record).unwrap();
    value.as_object_mut().unwrap().remove("view");
    std::fs::write(&run, value.to_string()).unwrap();
    let o = sfp(&["eval", v, r]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_clean_failure(&o, "records no view");
    // A folder where the record should be.
    std::fs::remove_file(&run).unwrap();
    std::fs::create_dir(&run).unwrap();
    let o = sfp(&["eval", v, r]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_clean_failure(&o, "run.json");
    // None at all: scored, with a warning.
    std::fs::remove_dir(&run).unwrap();
    let o = sfp_ok(&["eval", v, r]);
    assert!(stderr(&o).contains("warning") && stderr(&o).contains("cannot be checked"));
}
