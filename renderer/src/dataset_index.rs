//! `dataset.json`, a dataset folder's index (conventions.md §5): its views
//! in order and the settings they were rendered with. `sfp dataset` writes
//! it; `sfp reconstruct` and the sweeps read the views from it. Writer and
//! reader are one type, so they agree.

use serde::{Deserialize, Serialize};
use sfp_core::{Error, Result, io};
use std::path::Path;

/// The file's name in a dataset folder.
pub const FILE: &str = "dataset.json";

/// The index. Only `views` (each with its `folder`) is required on reading,
/// so an index written by hand or by another tool works.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DatasetIndex {
    #[serde(default)]
    pub schema_version: u32,
    #[serde(default)]
    pub generator: String,
    #[serde(default)]
    pub version: String,
    #[serde(default)]
    pub name: String,
    #[serde(default)]
    pub preset_file: String,
    /// The preset after overrides (`DatasetDesc`).
    #[serde(default)]
    pub settings: serde_json::Value,
    pub views: Vec<IndexedView>,
}

/// One view of the index.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IndexedView {
    /// The view's folder, a name inside the dataset folder.
    pub folder: String,
    /// The object it shows; readers fall back on the folder's name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub object: Option<String>,
    /// Index among the object's views.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub view: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub view_index: Option<u64>,
    /// The object's orientation (XYZ degrees).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotate: Option<[f64; 3]>,
    /// The preset's `[[lighting]]` the view was lit by, if it has any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lighting: Option<String>,
}

impl DatasetIndex {
    /// Writes `dir/dataset.json` (keys sorted, as a JSON tree prints them).
    pub fn write(&self, dir: &Path) -> Result<()> {
        let path = dir.join(FILE);
        let tree = serde_json::to_value(self)
            .map_err(|e| Error::file(&path, format!("cannot write the index: {e}")))?;
        let text = serde_json::to_vec_pretty(&tree).expect("a JSON tree serialises");
        io::write_atomic(&path, &text)
    }

    /// Reads `dir/dataset.json`: at least one view, each folder a plain
    /// name inside `dir`.
    pub fn read(dir: &Path) -> Result<DatasetIndex> {
        let path = dir.join(FILE);
        let bytes = std::fs::read(&path).map_err(|e| Error::read(&path, e))?;
        let index: DatasetIndex = serde_json::from_slice(&bytes)
            .map_err(|e| Error::file(&path, format!("invalid dataset.json: {e}")))?;
        for (i, v) in index.views.iter().enumerate() {
            if v.folder.is_empty() || Path::new(&v.folder).components().count() != 1 {
                return Err(Error::file(
                    &path,
                    format!("views[{i}].folder: not a folder name"),
                ));
            }
        }
        if index.views.is_empty() {
            return Err(Error::file(&path, "lists no views"));
        }
        Ok(index)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_index_reads_back_and_a_bad_one_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let index = DatasetIndex {
            schema_version: 1,
            generator: "sfp-renderer".into(),
            version: "0.1.0".into(),
            name: "tiny".into(),
            preset_file: "tiny.toml".into(),
            settings: serde_json::json!({"b": 1, "a": [0.5]}),
            views: vec![IndexedView {
                folder: "ball_0".into(),
                object: Some("ball".into()),
                view: Some(0),
                view_index: Some(3),
                rotate: Some([0.0, 90.0, 0.0]),
                lighting: Some("sky".into()),
            }],
        };
        index.write(dir.path()).unwrap();
        assert_eq!(DatasetIndex::read(dir.path()).unwrap(), index);
        let path = dir.path().join(FILE);
        for (text, expected) in [
            (r#"{"views": [{"folder": "../x"}]}"#, "views[0].folder"),
            (r#"{"views": []}"#, "lists no views"),
            (r#"{"name": "x"}"#, "invalid dataset.json"),
        ] {
            std::fs::write(&path, text).unwrap();
            let e = DatasetIndex::read(dir.path()).unwrap_err().to_string();
            assert!(e.contains("dataset.json") && e.contains(expected), "{e}");
        }
        std::fs::write(&path, r#"{"views": [{"folder": "cup_2"}]}"#).unwrap();
        assert_eq!(
            DatasetIndex::read(dir.path()).unwrap().views[0].object,
            None
        );
    }
}
