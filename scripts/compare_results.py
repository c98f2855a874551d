#!/usr/bin/env python3
"""Compares two `warpcheck validate --json` files result by result.

A result is keyed by (kernel, scalar, config, test); --rename gives a case BEFORE's key under AFTER's names. Two results agree when their statistic and p-value are the same
doubles, their verdicts are the same and their detail texts are the same after --replace. Only the cases both files
hold are compared (a killed run keeps the cases it finished); the others are counted. A statistical test's verdict
is compared only when both files hold the same cases, since the correction for multiple tests spans the file.
Exit status: 0 when every compared result agrees, 1 when any differs, 2 on bad input.

  scripts/compare_results.py BEFORE.json AFTER.json [--replace OLD=NEW]... [--rename K/C=K/C]... [--show N]
"""
import argparse
import json
import sys


def bad_input(message):
    print(f"compare_results: {message}", file=sys.stderr)
    sys.exit(2)


def load(path):
    try:
        with open(path) as f:
            doc = json.load(f)
    except (OSError, ValueError) as e:
        bad_input(f"cannot read '{path}': {e}")
    if not isinstance(doc, dict) or not isinstance(doc.get("results"), list):
        bad_input(f"'{path}' is not a warpcheck validate --json file (no \"results\" list)")
    return doc


def by_key(doc, renames={}):
    out = {}
    for r in doc["results"]:
        kernel, config = renames.get((r["kernel"], r["config"]), (r["kernel"], r["config"]))
        out[(kernel, r["scalar"], config, r["test"])] = r
    return out


def differences(a, b, replacements, verdicts):
    """The fields in which two results with the same key disagree; statistical verdicts only when `verdicts`."""
    out = []
    for field in ("statistic", "p_value"):
        if a.get(field) != b.get(field):  # the same double: both files print it to round trip
            out.append(f"{field} {a.get(field)!r} -> {b.get(field)!r}")
    if (verdicts or a.get("p_value") is None) and a.get("passed") != b.get("passed"):
        out.append(f"passed {a.get('passed')} -> {b.get('passed')}")
    detail_a = a.get("detail", "")
    for old, new in replacements:
        detail_a = detail_a.replace(old, new)
    if detail_a != b.get("detail", ""):
        out.append(f"detail {a.get('detail', '')!r} -> {b.get('detail', '')!r}")
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("before")
    p.add_argument("after")
    p.add_argument("--replace", action="append", default=[], metavar="OLD=NEW",
                   help="text replaced in BEFORE's detail before comparing (a renamed file, say)")
    p.add_argument("--rename", action="append", default=[], metavar="KERNEL/CONFIG=KERNEL/CONFIG",
                   help="a case of BEFORE compared with the case of AFTER so named (a renamed kernel, say)")
    p.add_argument("--show", type=int, default=20, help="differences printed (default 20)")
    a = p.parse_args()
    replacements = []
    for r in a.replace:
        if "=" not in r:
            bad_input(f"--replace takes OLD=NEW, not '{r}'")
        replacements.append(tuple(r.split("=", 1)))

    renames = {}
    for r in a.rename:
        old, _, new = r.partition("=")
        if old.count("/") != 1 or new.count("/") != 1:
            bad_input(f"--rename takes KERNEL/CONFIG=KERNEL/CONFIG, not '{r}'")
        renames[tuple(old.split("/"))] = tuple(new.split("/"))

    before, after = by_key(load(a.before), renames), by_key(load(a.after))
    case = lambda k: k[:3]
    cases_before, cases_after = {case(k) for k in before}, {case(k) for k in after}
    common = cases_before & cases_after
    # A statistical test's verdict is corrected (Holm, Sidak) over all of its file's tests: compared only when both
    # files hold the same cases.
    verdicts = cases_before == cases_after
    compared = differing = 0
    only = {"before": [], "after": []}
    for key in sorted(set(before) | set(after)):
        if case(key) not in common:
            continue
        if key not in after or key not in before:
            only["before" if key in before else "after"].append(key)
            continue
        compared += 1
        d = differences(before[key], after[key], replacements, verdicts)
        if d:
            differing += 1
            if differing <= a.show:
                print(" ".join(key) + ": " + "; ".join(d))
    print(f"cases: {len(cases_before)} before, {len(cases_after)} after, {len(common)} in both")
    print(f"results compared: {compared}, differing: {differing}" +
          ("" if verdicts else " (statistical verdicts not compared: the files hold different cases)"))
    for side, keys in only.items():
        if keys:
            print(f"tests only {side} in common cases: {len(keys)} (e.g. {' '.join(keys[0])})")
    return 1 if differing or any(only.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
