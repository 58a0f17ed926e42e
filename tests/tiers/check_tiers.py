#!/usr/bin/python3
"""Fails, naming each offender, when a test of the build has no tier label, more than one, or a
timeout other than its tier's (tests/CMakeLists.txt, cmake/Tiers.cmake).

usage: check_tiers.py CTEST BUILD_DIR unit=60 integration=300 acceptance=900
"""
import json
import subprocess
import sys


def main():
    ctest, build = sys.argv[1], sys.argv[2]
    timeouts = dict((k, float(v)) for k, v in (a.split("=") for a in sys.argv[3:]))
    listing = subprocess.run([ctest, "--show-only=json-v1"], cwd=build, check=True,
                             capture_output=True, text=True).stdout
    tests = json.loads(listing)["tests"]
    if not tests:
        print("no tests registered in %s" % build)
        return 1
    offenders = []
    counts = dict.fromkeys(timeouts, 0)
    for test in tests:
        props = {p["name"]: p["value"] for p in test.get("properties", [])}
        tiers = [label for label in props.get("LABELS", []) if label in timeouts]
        if len(tiers) != 1:
            offenders.append("%s: tiers %s, expected exactly one of %s"
                             % (test["name"], tiers, sorted(timeouts)))
            continue
        counts[tiers[0]] += 1
        if float(props.get("TIMEOUT", -1)) != timeouts[tiers[0]]:
            offenders.append("%s: timeout %s s, its tier %s has %g s"
                             % (test["name"], props.get("TIMEOUT"), tiers[0], timeouts[tiers[0]]))
    if offenders:
        print("%d of %d tests break the tier rule (tests/CMakeLists.txt):\n  %s"
              % (len(offenders), len(tests), "\n  ".join(offenders)))
        return 1
    print("tiers: %d tests, each in exactly one tier: %s"
          % (len(tests), ", ".join("%s %d" % kv for kv in counts.items())))
    return 0


if __name__ == "__main__":
    sys.exit(main())
