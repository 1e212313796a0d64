#!/usr/bin/env python3
"""Compares the metrics.json of two sets of runs, field by field, ignoring timing and wall-clock fields.

  scripts/compare-metrics.py BEFORE_DIR AFTER_DIR [--ignore FIELD ...]

Each DIR holds one folder per scenario (as `stvl-bench run --out DIR/<name>` writes them) or is itself a run
folder. FIELD is a dotted path (evaluation.mean.phantom_obstacles); a prefix ignores everything below it.
Prints one line per scenario (identical, or each differing field with both values) and exits 1 when any
field not ignored differs or a scenario is missing on one side, 0 otherwise.
"""
import argparse
import json
import os
import sys

# Fields that measure the machine, not the run, wherever they are.
TIMING = ("timing_ms", "real_time_factor", "wall_time_s")


def runs(root):
    if os.path.isfile(os.path.join(root, "metrics.json")):
        return {os.path.basename(os.path.normpath(root)): os.path.join(root, "metrics.json")}
    found = {}
    for name in sorted(os.listdir(root)):
        path = os.path.join(root, name, "metrics.json")
        if os.path.isfile(path):
            found[name] = path
    return found


def flatten(value, prefix, out):
    if isinstance(value, dict):
        for key, item in value.items():
            flatten(item, prefix + "." + key if prefix else key, out)
    elif isinstance(value, list):
        out[prefix + ".length"] = len(value)
        for i, item in enumerate(value):
            flatten(item, "%s[%d]" % (prefix, i), out)
    else:
        out[prefix] = value


def ignored(field, prefixes):
    if any(part in TIMING for part in field.replace("[", ".").split(".")):
        return True  # a timing at any depth (navigation.timing_ms.planner)
    for p in prefixes:
        if field == p or field.startswith(p + ".") or field.startswith(p + "["):
            return True
    return False


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("--ignore", action="append", default=[], help="dotted field path (repeatable)")
    args = parser.parse_args()
    prefixes = list(TIMING) + args.ignore
    before, after = runs(args.before), runs(args.after)
    if not before and not after:
        print("compare-metrics: no metrics.json under %s or %s" % (args.before, args.after), file=sys.stderr)
        return 2
    status = 0
    for name in sorted(set(before) | set(after)):
        if name not in before or name not in after:
            print("%s: only in %s" % (name, args.before if name in before else args.after))
            status = 1
            continue
        a, b = {}, {}
        with open(before[name]) as f:
            flatten(json.load(f), "", a)
        with open(after[name]) as f:
            flatten(json.load(f), "", b)
        diffs = [k for k in sorted(set(a) | set(b)) if not ignored(k, prefixes) and a.get(k, "<absent>") != b.get(k, "<absent>")]
        skipped = sorted({p for p in args.ignore for k in set(a) | set(b) if ignored(k, [p]) and a.get(k) != b.get(k)})
        note = " (differs only in ignored %s)" % ", ".join(skipped) if skipped and not diffs else ""
        if not diffs:
            print("%s: identical except timing%s" % (name, note))
            continue
        status = 1
        print("%s: %d fields differ" % (name, len(diffs)))
        for k in diffs[:40]:
            print("  %s: %r -> %r" % (k, a.get(k, "<absent>"), b.get(k, "<absent>")))
        if len(diffs) > 40:
            print("  ... %d more" % (len(diffs) - 40))
    return status


if __name__ == "__main__":
    sys.exit(main())
