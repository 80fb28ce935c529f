#!/usr/bin/env python3
"""Mutation testing of the gateware: every mutant of scripts/mutants/list.toml
must be caught by its check.

Each mutant names a file, an exact original text (it must occur exactly once
in that file), its replacement, why it matters, and the check that must
catch it (a named check of the list's [checks]: commands run in order until
one fails; default "hdl", i.e. `cargo test --release -p gyrocal-hdl` in
three stages, unit tests first). An entry marked
`equivalent = "why"` is a mutant that no test can catch, because it changes
nothing observable; it is checked to apply but not run. An entry marked
`compile_time = "what stops it"` is one the compiler must refuse (a const
assertion ties the value to its other home): its build error is its catch,
and a mutant that builds is judged by its check as any other.

How a run works:
  1. The working tree (tracked files and untracked, not ignored ones, as they
     are now) is copied into a scratch tree, target/mutants/tree; the working
     tree itself is never modified. Unchanged files keep their times, so
     cargo rebuilds only what a mutant touches; all mutants share one
     target folder, target/mutants/target.
  2. Each check the selected mutants use runs once on the unmutated tree
     and must pass (the baseline; its time sets the timeout).
  3. For each mutant: the replacement is written into the scratch tree;
     for a check with `export = true` the Verilog is re-exported there
     (`cargo run --release -- export`); the check runs; the file and
     verilog-out/ are restored. Verdict: caught (the check failed; the
     failing tests are named), timeout (caught: the check ran past
     `TIMEOUT_FACTOR` times its baseline and a margin), survived (the
     check passed), or
     build error (the mutant does not compile: a broken list entry).
  4. The result table is written after every mutant (RESULTS.md).
The proofs use the repository's YoWASP venv (.venv-fpga, or the one
GYROCAL_FPGA_VENV names: scripts/fpga/install-venv.sh makes it).

Usage:
  scripts/mutants/run.py                 all mutants; writes scripts/mutants/RESULTS.md
  scripts/mutants/run.py --only ID ...   some; writes target/mutants/RESULTS.md
  scripts/mutants/run.py --check-list    only check that every entry applies
Exit status: 0 when every run mutant was caught, 1 otherwise, 2 on bad input.
"""

import argparse
import datetime
import os
import pathlib
import re
import shutil
import signal
import subprocess
import sys
import time
import tomllib

HERE = pathlib.Path(__file__).resolve().parent
# A check that runs past TIMEOUT_FACTOR times its baseline plus
# TIMEOUT_MARGIN seconds is stopped (verdict "timeout"): generous, since the
# machine's load varies during a run of hours.
TIMEOUT_FACTOR = 4
TIMEOUT_MARGIN = 600
EXPORT = ["cargo", "run", "--release", "--quiet", "--", "export"]
ENTRY_KEYS = {"id", "file", "original", "replacement", "why", "check", "equivalent",
              "compile_time"}


class ListError(Exception):
    """A list entry that cannot be used (one line: what and where)."""


def load_list(path, root):
    """The checks and mutants of the list file, validated against `root`."""
    try:
        data = tomllib.loads(pathlib.Path(path).read_text())
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise ListError(f"{path}: {e}")
    checks = data.get("checks", {})
    for name, check in checks.items():
        stages = check.get("stages")
        if not (isinstance(stages, list) and stages
                and all(isinstance(s, list) and s and all(isinstance(a, str) for a in s)
                        for s in stages)):
            raise ListError(f"{path}: check {name!r} needs `stages`, a list of commands "
                            "(each a non-empty list of strings)")
    mutants = data.get("mutant", [])
    if not mutants:
        raise ListError(f"{path}: no [[mutant]] entries")
    seen = set()
    problems = []
    for n, m in enumerate(mutants):
        where = f"{path}: mutant {m.get('id', '#' + str(n + 1))}"
        problems += [f"{where}: {p}" for p in entry_problems(m, checks, root, seen)]
        seen.add(m.get("id"))
    if problems:
        raise ListError("\n".join(problems))
    return checks, mutants


def entry_problems(m, checks, root, seen):
    """What is wrong with one entry (empty when it applies)."""
    missing = [k for k in ("id", "file", "original", "replacement", "why") if k not in m]
    if missing:
        return [f"missing {', '.join(missing)}"]
    problems = [f"unknown key {k!r} (allowed: {sorted(ENTRY_KEYS)})" for k in m if k not in ENTRY_KEYS]
    if m["id"] in seen:
        problems.append("id used twice")
    if m.get("check", "hdl") not in checks:
        problems.append(f"check {m.get('check', 'hdl')!r} is not in [checks] ({sorted(checks)})")
    if m["original"] == m["replacement"]:
        problems.append("replacement equals original")
    try:
        text = (root / m["file"]).read_text()
    except OSError as e:
        return problems + [f"{m['file']}: {e.strerror}"]
    count = text.count(m["original"])
    if count != 1:
        problems.append(f"original text occurs {count} times in {m['file']} (must be exactly once)")
    return problems


def tree_files(root):
    """Tracked and untracked (not ignored) files of the working tree."""
    out = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=root, check=True, capture_output=True).stdout
    return [f for f in out.decode().split("\0") if f and (root / f).is_file()]


def sync_tree(root, tree):
    """Make `tree` a copy of the working tree as it is now; returns the
    copy's files (path: bytes), which `restore` puts back after each
    mutant (so later edits of the working tree do not leak into a run)."""
    files = {f: (root / f).read_bytes() for f in tree_files(root)}
    restore(tree, files)
    return files


def restore(tree, files):
    """Write back every file of `files` that differs in `tree` (with a new
    modification time, so cargo rebuilds what it feeds; the others keep
    their builds) and remove the files `files` lacks (an export's
    leftovers)."""
    tree.mkdir(parents=True, exist_ok=True)
    for f, content in files.items():
        dst = tree / f
        if not dst.is_file() or dst.read_bytes() != content:
            dst.parent.mkdir(parents=True, exist_ok=True)
            dst.write_bytes(content)
    for dst in tree.rglob("*"):
        if dst.is_file() and dst.relative_to(tree).as_posix() not in files:
            dst.unlink()


def failing_tests(log):
    """`binary: test` for every failed test in a cargo test log."""
    found, binary = [], "?"
    for line in log.splitlines():
        running = re.match(r"\s*Running (?:unittests )?(\S+)", line)
        if running:
            binary = pathlib.Path(running.group(1)).stem
        elif line.strip().startswith("Doc-tests"):
            binary = "doc"
        failed = re.match(r"test (.+?) \.\.\. FAILED", line)
        if failed:
            found.append(f"{binary}: {failed.group(1)}")
    return found


def run_command(command, cwd, env, timeout):
    """(exit status or None on timeout, merged output, seconds)."""
    start = time.monotonic()
    proc = subprocess.Popen(command, cwd=cwd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, start_new_session=True)
    try:
        out, _ = proc.communicate(timeout=timeout)
        status = proc.returncode
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        status = None
    return status, out.decode(errors="replace"), time.monotonic() - start


def run_check(check, tree, env, timeout):
    """Export if the check reads the Verilog, then run its stages until one
    fails: a verdict dict."""
    start = time.monotonic()
    if check.get("export"):
        status, log, _ = run_command(EXPORT, tree, env, timeout)
        if status != 0:
            return {"verdict": "export failed", "tests": [],
                    "seconds": time.monotonic() - start, "log": log}
    for stage in check["stages"]:
        left = None if timeout is None else max(1.0, timeout - (time.monotonic() - start))
        status, log, _ = run_command(stage, tree, env, left)
        if status != 0:
            break
    seconds = time.monotonic() - start
    if status is None:
        verdict = "timeout"
    elif status == 0:
        verdict = "survived"
    elif re.search(r"^error(\[E\d+\])?: could not compile|^error\[E\d+\]", log, re.M):
        verdict = "build error"
    else:
        verdict = "caught"
    return {"verdict": verdict, "tests": failing_tests(log), "seconds": seconds, "log": log}


def run_mutant(m, checks, files, tree, env, baselines):
    check = checks[m.get("check", "hdl")]
    path = tree / m["file"]
    text = path.read_text()
    path.write_text(text.replace(m["original"], m["replacement"], 1))
    timeout = TIMEOUT_FACTOR * baselines[m.get("check", "hdl")] + TIMEOUT_MARGIN
    try:
        return run_check(check, tree, env, timeout)
    finally:
        restore(tree, files)  # the file, and an export's output


def markdown(rows, checks, baselines, started, wall, complete):
    """The result table."""
    counts = {}
    for r in rows:
        counts[r["verdict"]] = counts.get(r["verdict"], 0) + 1
    head = [
        "# Mutation testing of the gateware",
        "",
        "Written by `scripts/mutants/run.py` from `scripts/mutants/list.toml`; do not edit.",
        "Each mutant is one edit of the gateware or its models; its check must fail.",
        "",
        f"- Run started {started:%Y-%m-%d %H:%M} UTC on {os.cpu_count()} cores; "
        f"wall time {fmt_time(wall)}{'' if complete else ' so far (incomplete run)'}.",
        f"- Result: {len(rows)} mutants: "
        + ", ".join(f"{n} {v}" for v, n in sorted(counts.items())) + ".",
    ]
    for name, check in checks.items():
        if name in baselines:
            stages = " then ".join(f"`{' '.join(s)}`" for s in check["stages"])
            head.append(f"- Check `{name}`: {stages}"
                        f"{' after re-export' if check.get('export') else ''}; "
                        f"baseline (unmutated) {fmt_time(baselines[name])}.")
    table = ["", "| mutant | file | check | verdict | failing tests (first 3) | time |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        tests = "; ".join(f"`{t}`" for t in r["tests"][:3]) or r.get("note", "")
        table.append(f"| {r['id']} | {r['file']} | {r['check']} | {r['verdict']} | "
                     f"{tests.replace('|', '/')} | {fmt_time(r['seconds'])} |")
    return "\n".join(head + table) + "\n"


def fmt_time(seconds):
    seconds = int(round(seconds))
    return f"{seconds // 3600}:{seconds // 60 % 60:02d}:{seconds % 60:02d}"


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--root", type=pathlib.Path, default=HERE.parent.parent,
                   help="the repository (default: this script's)")
    p.add_argument("--list", type=pathlib.Path, help="default ROOT/scripts/mutants/list.toml")
    p.add_argument("--work", type=pathlib.Path, help="default ROOT/target/mutants")
    p.add_argument("--results", type=pathlib.Path,
                   help="default ROOT/scripts/mutants/RESULTS.md, WORK/RESULTS.md with --only")
    p.add_argument("--only", nargs="+", metavar="ID", help="run only these mutants")
    p.add_argument("--check-list", action="store_true",
                   help="only check that every entry applies")
    return p.parse_args(argv)


def main(argv):
    args = parse_args(argv)
    root = args.root.resolve()
    list_path = args.list or root / "scripts/mutants/list.toml"
    work = (args.work or root / "target/mutants").resolve()
    try:
        checks, mutants = load_list(list_path, root)
        if args.only:
            unknown = set(args.only) - {m["id"] for m in mutants}
            if unknown:
                raise ListError(f"--only: no mutant {sorted(unknown)} in {list_path}")
            mutants = [m for m in mutants if m["id"] in args.only]
    except ListError as e:
        print(e, file=sys.stderr)
        return 2
    if args.check_list:
        print(f"{list_path}: {len(mutants)} mutants apply")
        return 0
    results = args.results or (work / "RESULTS.md" if args.only
                               else root / "scripts/mutants/RESULTS.md")
    return run_all(checks, mutants, root, work, results, complete_list=not args.only)


def run_all(checks, mutants, root, work, results, complete_list):
    started, t0 = datetime.datetime.now(datetime.timezone.utc), time.monotonic()
    tree = work / "tree"
    files = sync_tree(root, tree)
    # One target folder for every mutant, built incrementally: a mutant's
    # rebuild of the hdl crate takes seconds instead of minutes (measured:
    # 18 s against 240 s on the project's loaded 2-core machine), and the
    # tests run as fast.
    env = dict(os.environ, CARGO_TARGET_DIR=str(work / "target"), CARGO_INCREMENTAL="1")
    # A mutant needs its check to fail, not a minimal failing case: a
    # property test that fails shrinks its case first, re-simulating
    # thousands of clocks per shrink step. No shrinking, and no regression
    # files written into the scratch tree for later mutants to replay:
    # each check draws as its baseline did.
    env.update(PROPTEST_MAX_SHRINK_ITERS="0", PROPTEST_DISABLE_FAILURE_PERSISTENCE="true")
    # The scratch tree has no .venv-fpga (ignored files are not copied):
    # the proofs (check formal) use the repository's, or the one
    # GYROCAL_FPGA_VENV names, taken from the repository as the tests take
    # it (verify::tools::fpga_venv).
    env["GYROCAL_FPGA_VENV"] = str(root / (os.environ.get("GYROCAL_FPGA_VENV") or ".venv-fpga"))
    baselines = {}
    for name in sorted({m.get("check", "hdl") for m in mutants if "equivalent" not in m}):
        print(f"baseline: check {name} on the unmutated tree ...", flush=True)
        r = run_check(checks[name], tree, env, None)
        if r["verdict"] != "survived":
            print(f"baseline check {name} fails on the unmutated tree ({r['verdict']}):\n"
                  + "\n".join(r["log"].splitlines()[-30:]), file=sys.stderr)
            return 1
        baselines[name] = r["seconds"]
        print(f"baseline: check {name} passes in {fmt_time(r['seconds'])}", flush=True)
    rows = []
    for n, m in enumerate(mutants):
        row = {"id": m["id"], "file": m["file"], "check": m.get("check", "hdl")}
        if "equivalent" in m:
            row.update(verdict="equivalent", tests=[], seconds=0.0, note=m["equivalent"])
        else:
            row.update(run_mutant(m, checks, files, tree, env, baselines))
            if "compile_time" in m and row["verdict"] == "build error":
                first = next((line for line in row["log"].splitlines()
                              if line.startswith("error")), "")
                row.update(verdict="caught", tests=[f"compiler: {first}"],
                           note=m["compile_time"])
            elif row["verdict"] in ("build error", "export failed"):
                row["note"] = row["log"].splitlines()[-1] if row["log"] else ""
        row.pop("log", None)
        rows.append(row)
        print(f"[{n + 1}/{len(mutants)}] {m['id']}: {row['verdict']} "
              f"({fmt_time(row['seconds'])}) {'; '.join(row['tests'][:3])}", flush=True)
        complete = complete_list and n + 1 == len(mutants)
        results.parent.mkdir(parents=True, exist_ok=True)
        results.write_text(markdown(rows, checks, baselines, started,
                                    time.monotonic() - t0, complete))
    print(f"wrote {results}")
    return 0 if all(r["verdict"] in ("caught", "timeout", "equivalent") for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
