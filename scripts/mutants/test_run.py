#!/usr/bin/env python3
"""Tests of scripts/mutants/run.py on a tiny repository with a cheap check
(a Python one-liner standing in for `cargo test`): each verdict, the
failing test's name, the untouched working tree, the re-export, and the
list errors. Run: python3 scripts/mutants/test_run.py (tests/mutants_list.rs
runs it)."""

import pathlib
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import run  # noqa: E402

# The "test suite": fails, naming a test as cargo does, unless gain.txt says 2.
CHECK = ("import sys; g = open('gain.txt').read().strip();"
         "print('     Running tests/gain.rs (x)');"
         "print('test gain_is_two ... ' + ('ok' if g == '2' else 'FAILED'));"
         "sys.exit(0 if g == '2' else 101)")

LIST = f'''
[checks.hdl]
stages = [["python3", "-c", "print('unit tests ok')"], ["python3", "-c", "{CHECK}"]]

[checks.exported]
export = true
stages = [["python3", "-c", "import sys; sys.exit(open('out/gain.v').read() != 'gain 2')"]]

[[mutant]]
id = "caught"
file = "gain.txt"
original = "2"
replacement = "3"
why = "the gain changes"

[[mutant]]
id = "survivor"
file = "notes.txt"
original = "note"
replacement = "remark"
why = "nothing reads the notes"

[[mutant]]
id = "skipped"
file = "notes.txt"
original = "a note"
replacement = "a remark"
why = "same"
equivalent = "nothing reads the notes"

[[mutant]]
id = "broken"
file = "gain.txt"
original = "2"
replacement = "x"
why = "does not parse"
check = "hdl"

[[mutant]]
id = "export-caught"
file = "gain.txt"
original = "2"
replacement = "4"
why = "the export changes"
check = "exported"
'''


def make_repo(root):
    (root / "gain.txt").write_text("2\n")
    (root / "notes.txt").write_text("a note\n")
    (root / "out").mkdir()
    (root / "out/gain.v").write_text("gain 2")
    (root / "list.toml").write_text(LIST)
    subprocess.run(["git", "init", "-q"], cwd=root, check=True)
    subprocess.run(["git", "add", "."], cwd=root, check=True)


class RunTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.root = pathlib.Path(self.tmp.name)
        make_repo(self.root)
        # The "export": writes out/gain.v from gain.txt, like `gyrocal export`.
        run.EXPORT = ["python3", "-c",
                      "open('out/gain.v', 'w').write('gain ' + open('gain.txt').read().strip())"]
        # A mutant that does not build: the check's first stage fails with cargo's words.
        self.broken_stage = ["python3", "-c",
                             "import sys; g = open('gain.txt').read().strip();"
                             "print('error: could not compile `gain`') if g == 'x' else None;"
                             "sys.exit(101 if g == 'x' else 0)"]

    def tearDown(self):
        self.tmp.cleanup()

    def run_main(self, *extra):
        return run.main(["--root", str(self.root), "--list", str(self.root / "list.toml"),
                         "--results", str(self.root / "RESULTS.md"), *extra])

    def test_verdicts_names_and_untouched_tree(self):
        checks, mutants = run.load_list(self.root / "list.toml", self.root)
        checks["hdl"]["stages"].insert(0, self.broken_stage)
        work = self.root / "target/mutants"
        status = run.run_all(checks, mutants, self.root, work, self.root / "RESULTS.md", True)
        self.assertEqual(status, 1)  # a survivor and a build error
        table = (self.root / "RESULTS.md").read_text()
        rows = {line.split(" | ")[0].lstrip("| "): line for line in table.splitlines()
                if line.startswith("| ") and not line.startswith("| mutant")}
        self.assertIn("| caught | `gain: gain_is_two` |", rows["caught"])
        self.assertIn("| survived |", rows["survivor"])
        self.assertIn("| equivalent | nothing reads the notes |", rows["skipped"])
        self.assertIn("| build error | error: could not compile `gain` |", rows["broken"])
        self.assertIn("| exported | caught |", rows["export-caught"])
        self.assertIn("5 mutants: 1 build error, 2 caught, 1 equivalent, 1 survived", table)
        # The working tree is untouched; the scratch tree is restored.
        self.assertEqual((self.root / "gain.txt").read_text(), "2\n")
        self.assertEqual((work / "tree/gain.txt").read_text(), "2\n")
        self.assertEqual((work / "tree/out/gain.v").read_text(), "gain 2")

    def test_only_runs_the_named_mutants(self):
        self.assertEqual(self.run_main("--only", "caught"), 0)
        table = (self.root / "RESULTS.md").read_text()
        self.assertIn("1 mutants: 1 caught", table)

    def test_list_errors_are_one_line_each(self):
        self.assertEqual(self.run_main("--check-list"), 0)
        (self.root / "gain.txt").write_text("22\n")
        with self.assertRaises(run.ListError) as e:
            run.load_list(self.root / "list.toml", self.root)
        self.assertIn("mutant caught: original text occurs 2 times in gain.txt", str(e.exception))
        self.assertEqual(self.run_main("--check-list"), 2)
        self.assertEqual(self.run_main("--only", "nonesuch"), 2)


if __name__ == "__main__":
    unittest.main()
