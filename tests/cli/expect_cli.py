#!/usr/bin/env python3
"""Runs one lmbake command and asserts its exit code and messages.

usage: expect_cli.py --exit N [--stderr RE]... [--no-stderr RE]... [--stdout RE]... [--absent PATH]...
                     [--unchanged PATH]... -- COMMAND ARGS...

--stderr/--stdout: a regular expression that must match somewhere in that stream.
--no-stderr: a regular expression that must match nowhere in stderr (a stage that must not run).
--absent: a path that must not exist afterwards (nothing written on failure).
--unchanged: a file whose bytes must be the same after the command (input never touched);
  one that did not exist must still not exist.
"""
import argparse
import os
import re
import subprocess
import sys


def main():
    argv = sys.argv[1:]
    if "--" not in argv:
        sys.exit("expect_cli.py: missing -- before the command")
    split = argv.index("--")
    ap = argparse.ArgumentParser()
    ap.add_argument("--exit", type=int, required=True)
    ap.add_argument("--stderr", action="append", default=[])
    ap.add_argument("--no-stderr", action="append", default=[])
    ap.add_argument("--stdout", action="append", default=[])
    ap.add_argument("--absent", action="append", default=[])
    ap.add_argument("--unchanged", action="append", default=[])
    opts = ap.parse_args(argv[:split])
    cmd = argv[split + 1:]
    before = {p: open(p, "rb").read() if os.path.exists(p) else None for p in opts.unchanged}
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    failures = []
    if proc.returncode != opts.exit:
        failures.append(f"exit code {proc.returncode}, expected {opts.exit}")
    for rx in opts.stderr:
        if not re.search(rx, proc.stderr):
            failures.append(f"stderr does not match /{rx}/")
    for rx in opts.no_stderr:
        if re.search(rx, proc.stderr):
            failures.append(f"stderr matches /{rx}/, which it must not")
    for rx in opts.stdout:
        if not re.search(rx, proc.stdout):
            failures.append(f"stdout does not match /{rx}/")
    for p in opts.absent:
        if os.path.exists(p):
            failures.append(f"{p} exists but must not")
    for p, data in before.items():
        now = open(p, "rb").read() if os.path.exists(p) else None
        if now != data:
            failures.append(f"{p} was modified (or created)")
    if failures:
        print("command:", " ".join(cmd))
        print("--- stdout\n" + proc.stdout[-4000:])
        print("--- stderr\n" + proc.stderr[-4000:])
        for f in failures:
            print("FAIL:", f)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
