//! The exit-code contract of the README, command by command: 1 when the
//! system refused a read or write (worth a retry), 2 when the command line
//! or an input is wrong. The table is printed (`--nocapture`).

use crate::common::*;

fn args(a: &[&str]) -> Vec<String> {
    a.iter().map(|s| s.to_string()).collect()
}

/// How each command fails, with the code it must end with.
#[test]
fn every_command_ends_with_the_documented_code() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    sfp_ok(&["analytic", "--size", "32", "--out", &p("view")]);
    sfp_ok(&[
        "reconstruct",
        &p("view"),
        "--method",
        "atkinson",
        "--out",
        &p("result"),
    ]);
    std::fs::write(p("garbage.png"), "not a png").unwrap();
    std::fs::write(p("garbage.toml"), "[[[").unwrap();
    std::fs::create_dir(p("papers")).unwrap();
    std::fs::write(p("papers/thesis.pdf"), "x").unwrap();
    let sweep = p("sweep.toml");
    std::fs::write(
        &sweep,
        "[[views]]\nanalytic = \"sphere\"\nsize = 32\n[[methods]]\nmethod = \"atkinson\"\n",
    )
    .unwrap();
    // A folder the system will not let anyone create, root included.
    let refused = "/sys/sfp-exit-code-test";
    let (view, result, missing, garbage) = (p("view"), p("result"), p("missing"), p("garbage.png"));
    let pol = |i: usize| format!("{view}/input/pol_{:03}.png", i * 45);
    let (p0, p1, p2, p3) = (pol(0), pol(1), pol(2), pol(3));
    let cases: Vec<(&str, &str, Vec<String>, i32)> = vec![
        (
            "analytic",
            "unknown option",
            args(&["analytic", "--sise", "32"]),
            2,
        ),
        (
            "analytic",
            "out where the system refuses",
            args(&["analytic", "--size", "16", "--out", refused]),
            1,
        ),
        (
            "analytic",
            "out a foreign folder",
            args(&["analytic", "--out", &p("papers")]),
            2,
        ),
        (
            "render",
            "missing scene",
            args(&["render", &missing, "--out", &p("r")]),
            2,
        ),
        (
            "render",
            "bad scene",
            args(&["render", &p("garbage.toml"), "--out", &p("r")]),
            2,
        ),
        (
            "dataset",
            "missing preset file",
            args(&["dataset", &p("none.toml"), "--out", &p("d")]),
            2,
        ),
        (
            "dataset",
            "out a view",
            args(&["dataset", "builtin", "--size", "16", "--out", &view]),
            2,
        ),
        (
            "import",
            "missing image",
            args(&[
                "import",
                "--angles",
                &missing,
                &p1,
                &p2,
                &p3,
                "--out",
                &p("i"),
            ]),
            2,
        ),
        (
            "import",
            "bad image",
            args(&[
                "import",
                "--angles",
                &garbage,
                &p1,
                &p2,
                &p3,
                "--out",
                &p("i"),
            ]),
            2,
        ),
        (
            "import",
            "missing mask",
            args(&[
                "import",
                "--angles",
                &p0,
                &p1,
                &p2,
                &p3,
                "--mask",
                &missing,
                "--out",
                &p("i"),
            ]),
            2,
        ),
        (
            "import",
            "out where the system refuses",
            args(&["import", "--angles", &p0, &p1, &p2, &p3, "--out", refused]),
            1,
        ),
        (
            "reconstruct",
            "missing view",
            args(&[
                "reconstruct",
                &missing,
                "--method",
                "smith",
                "--out",
                &p("x"),
            ]),
            2,
        ),
        (
            "reconstruct",
            "missing config",
            args(&[
                "reconstruct",
                &view,
                "--method",
                "smith",
                "--config",
                &missing,
                "--out",
                &p("x"),
            ]),
            2,
        ),
        (
            "reconstruct",
            "unknown method option",
            args(&[
                "reconstruct",
                &view,
                "--method",
                "smith",
                "--set",
                "lamda=1",
                "--out",
                &p("x"),
            ]),
            2,
        ),
        (
            "reconstruct",
            "out where the system refuses",
            args(&[
                "reconstruct",
                &view,
                "--method",
                "atkinson",
                "--out",
                refused,
            ]),
            1,
        ),
        (
            "reconstruct",
            "out a view",
            args(&["reconstruct", &view, "--method", "atkinson", "--out", &view]),
            2,
        ),
        (
            "eval",
            "missing result",
            args(&["eval", &view, &missing]),
            2,
        ),
        (
            "eval",
            "missing view",
            args(&["eval", &missing, &result]),
            2,
        ),
        (
            "export",
            "missing input",
            args(&["export", &missing, "--out", &p("e")]),
            2,
        ),
        (
            "export",
            "out where the system refuses",
            args(&["export", &result, "--out", refused]),
            1,
        ),
        ("inspect", "missing view", args(&["inspect", &missing]), 2),
        (
            "demo",
            "out a view",
            args(&["demo", "--size", "16", "--out", &view]),
            2,
        ),
        (
            "demo",
            "out where the system refuses",
            args(&["demo", "--size", "16", "--out", refused]),
            1,
        ),
        (
            "bench",
            "missing sweep file",
            args(&["bench", &missing, "--out", &p("b")]),
            2,
        ),
        (
            "bench",
            "bad sweep file",
            args(&["bench", &p("garbage.toml"), "--out", &p("b")]),
            2,
        ),
        (
            "bench",
            "out where the system refuses",
            args(&["bench", &sweep, "--out", refused]),
            1,
        ),
        (
            "bench merge",
            "missing shard",
            args(&["bench", "merge", &missing, "--out", &p("m")]),
            2,
        ),
        (
            "bench report",
            "missing folder",
            args(&["bench", "report", &missing]),
            2,
        ),
    ];
    let mut table = String::from("| command | failure | exit code |\n|---|---|---|\n");
    let mut wrong = Vec::new();
    for (command, failure, args, expected) in &cases {
        let o = sfp(&args.iter().map(String::as_str).collect::<Vec<_>>());
        let code = o.status.code();
        assert!(!stderr(&o).contains("panicked"), "{args:?}: {}", stderr(&o));
        table.push_str(&format!(
            "| `{command}` | {failure} | {} |\n",
            code.unwrap_or(-1)
        ));
        if code != Some(*expected) {
            wrong.push(format!(
                "{args:?}: {code:?}, not {expected}: {}",
                stderr(&o)
            ));
        }
    }
    println!("{table}");
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
