#!/usr/bin/env python3
"""Compares two results.json files as `counterpoise merge` promises: equal JSON values once the
run metadata that describes how the run was made, not what it found, is removed
(metadata.timings, shard_timings, date, jobs and shards).

Usage: compare.py A/results.json B/results.json — exit 0 when equal, 1 (with the first
differences) otherwise. Numbers are compared as the JSON text holds them (shortest round-trip
decimals), so equal means bit-identical doubles."""
import json
import sys

IGNORED = ("timings", "shard_timings", "date", "jobs", "shards")


def load(path):
    with open(path) as f:
        # parse_float=str: compare the decimal text, not a re-rounded float
        doc = json.load(f, parse_float=str)
    for key in IGNORED:
        doc.get("metadata", {}).pop(key, None)
    return doc


def differences(a, b, path, out):
    if len(out) >= 10:
        return
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                out.append(f"{path}.{k}: only in {'the first' if k in a else 'the second'}")
            else:
                differences(a[k], b[k], f"{path}.{k}", out)
    elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b)):
            differences(x, y, f"{path}[{i}]", out)
    elif a != b:
        out.append(f"{path}: {json.dumps(a)[:80]} ≠ {json.dumps(b)[:80]}")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    a, b = load(sys.argv[1]), load(sys.argv[2])
    if a == b:
        aside = ", ".join(f"metadata.{key}" for key in IGNORED)
        print(f"identical ({aside} aside): {sys.argv[1]} = {sys.argv[2]}")
        return 0
    out = []
    differences(a, b, "", out)
    print(f"DIFFERENT: {sys.argv[1]} ≠ {sys.argv[2]}; first differences:")
    for line in out:
        print("  " + line)
    return 1


if __name__ == "__main__":
    sys.exit(main())
