#!/usr/bin/env python3
"""The CI sweep as a ratchet (issue 13; docs/gait.md, the sweep's section).

Runs `gait-eval --sweep` for seeds 1 and 2 (300 cases each) and 7 (1,000, the
issue's done-when) and compares the failing cases with the known list in
gait_sweep_known_failures.txt:
- a case that fails and is not on the list fails the test (a regression);
- a listed case that now passes fails it too, asking for the list to shrink,
  so the list only ever gets shorter and always says what is still broken.
The issue's own gate (every case within every limit) is the DISABLED entry
beside this one; it is enabled when the list is empty.

Usage: gait_sweep_ratchet.py MARIONETTE_BINARY KNOWN_FAILURES_FILE
"""
import json
import subprocess
import sys

RUNS = [(1, 300), (2, 300), (7, 1000)]


def known_failures(path):
    known = set()
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            text = line.split("#", 1)[0].strip()
            if not text:
                continue
            seed = text.split("-", 1)[0]
            if not seed.isdigit() or len(text.split()) != 1:
                sys.exit(f"{path}:{number}: expected one case id such as 7-0154, got {line.strip()!r}")
            known.add(text)
    return known


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: gait_sweep_ratchet.py MARIONETTE_BINARY KNOWN_FAILURES_FILE")
    binary, listing = sys.argv[1], sys.argv[2]
    known = known_failures(listing)
    failing = {}
    total = 0
    for seed, count in RUNS:
        run = subprocess.run([binary, "gait-eval", "--sweep", str(count), "--seed", str(seed), "--json"],
                             capture_output=True, text=True, check=False)
        if run.returncode not in (0, 1):
            sys.exit(f"gait-eval --sweep {count} --seed {seed} exited {run.returncode}: {run.stderr.strip()}")
        summary = json.loads(run.stdout)
        assert summary["cases"] == count and summary["passed"] + summary["failed"] == count, summary
        total += count
        for f in summary["failures"]:
            failing[f["case"]] = f"{f['ground']}: {f['problem']}"
    new = sorted(set(failing) - known)
    fixed = sorted(known - set(failing))
    print(f"{total} cases, {len(failing)} failing, all {len(known)} known" if not new and not fixed else
          f"{total} cases, {len(failing)} failing, {len(known)} known")
    for case in new:
        print(f"NEW FAILURE {case} ({failing[case]}): replay it with --out and fix it, or explain it in docs/gait.md")
    for case in fixed:
        print(f"NOW PASSES {case}: remove it from {listing}")
    return 1 if new or fixed else 0


if __name__ == "__main__":
    sys.exit(main())
