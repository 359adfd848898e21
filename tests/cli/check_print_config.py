#!/usr/bin/env python3
"""`lmbake bake --print-config`: prints every key of the effective config (the config file,
then the command-line overrides) as YAML that `-c` reads back to the same config: printing
what was printed gives the same text, and the overrides show in it. Light groups whose entries
leave a string unset (no match, no name) print without it and read back too.

usage: check_print_config.py LMBAKE CONFIG WORKDIR
"""
import os
import subprocess
import sys


def run(*args):
    r = subprocess.run(list(args), capture_output=True, text=True, timeout=60)
    if r.returncode != 0:
        print("FAIL: %s: exit %d: %s" % (" ".join(args), r.returncode, r.stderr))
        sys.exit(1)
    return r.stdout


def main():
    lmbake, config, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    first = run(lmbake, "bake", "--print-config", "-c", config, "--seed", "42", "--rays", "777", "--method", "cosine")
    for want in ("\nseed: 42\n", "\n  gather: 777\n", "\n  method: cosine\n", "\nirradiance_cache:\n"):
        if want not in first:
            print("FAIL: %r not in the printed config:\n%s" % (want, first))
            sys.exit(1)
    path = os.path.join(work, "printed.yaml")
    with open(path, "w") as f:
        f.write(first)
    second = run(lmbake, "bake", "--print-config", "-c", path)
    if second != first:
        print("FAIL: the printed config does not read back to itself:\n%s\n---\n%s" % (first, second))
        sys.exit(1)
    # list entries with strings left unset (a sky group without match, one_per_light without a
    # name) print without them, and read back
    groups = os.path.join(work, "groups.yaml")
    with open(groups, "w") as f:
        f.write("output:\n  light_groups:\n    - {name: sky, sky: true}\n"
                "    - {match: \"lamp*\", one_per_light: true, scale: 2}\n")
    printed = run(lmbake, "bake", "--print-config", "-c", groups)
    with open(path, "w") as f:
        f.write(printed)
    again = run(lmbake, "bake", "--print-config", "-c", path)
    want = '  light_groups: [{name: "sky", sky: true, emissive: false, one_per_light: false, scale: 1}, ' \
           '{match: "lamp*", sky: false, emissive: false, one_per_light: true, scale: 2}]'
    if again != printed or want not in printed:
        print("FAIL: light groups printed as %r, read back as %r" %
              ([l for l in printed.splitlines() if "light_groups" in l], [l for l in again.splitlines() if "light_groups" in l]))
        sys.exit(1)
    keys = sum(1 for line in first.splitlines() if ":" in line and not line.startswith("#"))
    print("ok: %d lines with keys, read back to the same text; overrides shown" % keys)


if __name__ == "__main__":
    main()
