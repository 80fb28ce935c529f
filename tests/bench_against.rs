//! `scripts/bench-against.sh`, the model engine's speed against a base
//! binary side by side: bad arguments are refused in one line with exit
//! status 2, before anything is built or run.

use std::process::Command;

#[test]
fn bad_arguments_are_refused_in_one_line_before_any_build() {
    let cases: [(&[&str], &str); 4] = [
        (&["4afc731", "0"], "ROUNDS = 0: allowed a whole number >= 1"),
        (&["4afc731", "two"], "ROUNDS = two"),
        (
            &["no-such-revision"],
            "BASE_REV = no-such-revision: not a revision",
        ),
        (&["4afc731", "1", "4096"], "CPU = 4096: allowed 0.."),
    ];
    for (args, want) in cases {
        let o = Command::new("bash")
            .arg("scripts/bench-against.sh")
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8(o.stderr).unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.starts_with("error: ") && err.contains(want),
            "{args:?}: {err}"
        );
        assert!(o.stdout.is_empty(), "{args:?}");
    }
}
