#!/usr/bin/env python3
"""Summaries of scripts/coverage.sh's two gcovr JSON files (the default tests, the battery).

usage: coverage_summary.py TESTS.json BATTERY.json SUMMARY.md UNTAKEN.md "WHAT THE BATTERY RUN WAS"

SUMMARY.md: per header of lib/warpcheck/, lines and branches reached by each run (percent and counts).
UNTAKEN.md: every branch of a sample or pdf function of lib/ (a function whose name contains "sample" or "pdf")
that the battery never takes, by file and line, with the function's name and whether the tests take it.
A line's branches are merged over the template instantiations and translation units (gcovr does that).
"""
import json
import sys


def load(path):
    with open(path) as f:
        return {entry["file"]: entry for entry in json.load(f)["files"]}


def counts(entry):
    lines = [l for l in entry["lines"] if not l.get("gcovr/noncode")]
    branches = [b for l in lines for b in l["branches"]]
    return (sum(l["count"] > 0 for l in lines), len(lines), sum(b["count"] > 0 for b in branches), len(branches))


def pct(hit, total):
    return f"{100.0 * hit / total:.1f} % ({hit}/{total})" if total else "-"


def function_at(entry, line):
    best = None
    for fn in entry.get("functions", []):
        if fn["lineno"] <= line and (best is None or fn["lineno"] > best["lineno"]):
            best = fn
    return best["name"] if best else "?"


def main():
    tests, battery, summary, untaken, what = sys.argv[1:6]
    t, b = load(tests), load(battery)
    files = sorted(set(t) | set(b))
    out = [f"| header | lines, tests | branches, tests | lines, battery | branches, battery |", "|---|---|---|---|---|"]
    total_t, total_b = [0] * 4, [0] * 4
    for f in files:
        ct = counts(t[f]) if f in t else (0, 0, 0, 0)
        cb = counts(b[f]) if f in b else (0, 0, 0, 0)
        total_t = [x + y for x, y in zip(total_t, ct)]
        total_b = [x + y for x, y in zip(total_b, cb)]
        out.append(f"| `{f}` | {pct(ct[0], ct[1])} | {pct(ct[2], ct[3])} | {pct(cb[0], cb[1])} | {pct(cb[2], cb[3])} |")
    out.append(f"| all of lib/ | {pct(total_t[0], total_t[1])} | {pct(total_t[2], total_t[3])} | "
               f"{pct(total_b[0], total_b[1])} | {pct(total_b[2], total_b[3])} |")
    with open(summary, "w") as f:
        f.write(f"Coverage of lib/ (gcc --coverage, gcovr; battery: {what})\n\n" + "\n".join(out) + "\n")

    rows = []
    for f in files:
        if f not in b:
            continue
        tlines = {l["line_number"]: l for l in t.get(f, {"lines": []})["lines"]}
        for l in b[f]["lines"]:
            name = function_at(b[f], l["line_number"])
            if "sample" not in name and "pdf" not in name:
                continue
            missed = [i for i, br in enumerate(l["branches"]) if br["count"] == 0]
            if not missed:
                continue
            tl = tlines.get(l["line_number"])
            by_tests = tl is not None and all(
                i < len(tl["branches"]) and tl["branches"][i]["count"] > 0 for i in missed)
            rows.append(f"| `{f}:{l['line_number']}` | {len(missed)} of {len(l['branches'])} | "
                        f"{'line not reached' if l['count'] == 0 else 'line reached'} | "
                        f"{'yes' if by_tests else 'no'} | `{name[:90]}` |")
    with open(untaken, "w") as f:
        f.write(f"Branches of lib/'s sample and pdf functions the battery never takes ({what})\n\n"
                "| where | branches untaken | line | tests take them | function |\n|---|---|---|---|---|\n")
        f.write("\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
