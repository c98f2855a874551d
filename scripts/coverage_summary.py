#!/usr/bin/env python3
"""Summaries of scripts/coverage.sh's two gcovr JSON files (the default tests, the battery).

usage: coverage_summary.py TESTS.json BATTERY.json SUMMARY.md UNTAKEN.md "WHAT THE BATTERY RUN WAS"
                           [--root DIR] [--reasons REASONS.tsv] [--json OUT.json] [--commit SHA]

SUMMARY.md: per header of lib/warpcheck/, lines and branches reached by each run (percent and counts).
UNTAKEN.md: every branch of a sample or pdf function of lib/ (a function whose name contains "sample" or "pdf")
that the battery never takes, by file and line, with the function's name, whether the tests take it and why the
battery does not: the row of REASONS.tsv (data/coverage/untaken-reasons.tsv, its README says the columns) whose
file and code text are the line's and whose function substring, if any, is in the function's name.
A line's branches are merged over the template instantiations and translation units (gcovr does that).
OUT.json: both, for the HTML report (warpcheck report reads data/coverage/summary.json).
Prints the number of untaken lines without a reason; the exit status is 0 either way (this is a measurement).
"""
import argparse
import csv
import json
import os


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


def load_reasons(path):
    if not path:
        return []
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f, delimiter="\t", quoting=csv.QUOTE_NONE))
    for r in rows:
        if set(r) != {"file", "function", "code", "reason"} or not r["reason"]:
            raise SystemExit(f"coverage_summary: {path}: a row without file, function, code and reason: {r}")
    return rows


def reason_for(reasons, file, function, code):
    """The reason of the row that matches; a row naming a function wins over one that does not."""
    match = [r for r in reasons if r["file"] == file and r["code"] == code and r["function"] in function]
    match.sort(key=lambda r: -len(r["function"]))
    return match[0]["reason"] if match else None


def source_line(root, file, number):
    try:
        with open(os.path.join(root, file)) as f:
            lines = f.read().split("\n")
        return lines[number - 1].strip() if 0 < number <= len(lines) else ""
    except OSError:
        return ""


def header_rows(t, b):
    rows = []
    for f in sorted(set(t) | set(b)):
        ct = counts(t[f]) if f in t else (0, 0, 0, 0)
        cb = counts(b[f]) if f in b else (0, 0, 0, 0)
        rows.append({"file": f, "tests": {"lines": list(ct[:2]), "branches": list(ct[2:])},
                     "battery": {"lines": list(cb[:2]), "branches": list(cb[2:])}})
    total = {run: {kind: [sum(r[run][kind][i] for r in rows) for i in (0, 1)] for kind in ("lines", "branches")}
             for run in ("tests", "battery")}
    return rows, total


def untaken_rows(t, b, root, reasons):
    rows = []
    for f in sorted(b):
        tlines = {l["line_number"]: l for l in t.get(f, {"lines": []})["lines"]}
        for l in b[f]["lines"]:
            name = function_at(b[f], l["line_number"])
            if "sample" not in name and "pdf" not in name:
                continue
            missed = [i for i, br in enumerate(l["branches"]) if br["count"] == 0]
            if not missed:
                continue
            tl = tlines.get(l["line_number"])
            code = source_line(root, f, l["line_number"])
            rows.append({"file": f, "line": l["line_number"], "function": name, "code": code,
                         "branches_untaken": len(missed), "branches": len(l["branches"]),
                         "line_reached": l["count"] > 0,
                         "tests_take_them": tl is not None and all(
                             i < len(tl["branches"]) and tl["branches"][i]["count"] > 0 for i in missed),
                         "reason": reason_for(reasons, f, name, code)})
    return rows


def cells(c):
    return f"{pct(*c['lines'])} | {pct(*c['branches'])}"


def main():
    p = argparse.ArgumentParser()
    for name in ("tests", "battery", "summary", "untaken", "what"):
        p.add_argument(name)
    p.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    p.add_argument("--reasons")
    p.add_argument("--json")
    p.add_argument("--commit", default="")
    a = p.parse_args()
    t, b = load(a.tests), load(a.battery)
    headers, total = header_rows(t, b)
    untaken = untaken_rows(t, b, a.root, load_reasons(a.reasons))

    out = ["| header | lines, tests | branches, tests | lines, battery | branches, battery |", "|---|---|---|---|---|"]
    out += [f"| `{h['file']}` | {cells(h['tests'])} | {cells(h['battery'])} |" for h in headers]
    out.append(f"| all of lib/ | {cells(total['tests'])} | {cells(total['battery'])} |")
    with open(a.summary, "w") as f:
        f.write(f"Coverage of lib/ (gcc --coverage, gcovr; battery: {a.what})\n\n" + "\n".join(out) + "\n")

    with open(a.untaken, "w") as f:
        f.write(f"Branches of lib/'s sample and pdf functions the battery never takes ({a.what})\n\n"
                "| where | branches untaken | line | tests take them | function | why the battery does not |\n"
                "|---|---|---|---|---|---|\n")
        for u in untaken:
            f.write(f"| `{u['file']}:{u['line']}` | {u['branches_untaken']} of {u['branches']} | "
                    f"{'line reached' if u['line_reached'] else 'line not reached'} | "
                    f"{'yes' if u['tests_take_them'] else 'no'} | `{u['function'][:90]}` | "
                    f"{u['reason'] or '**not explained**'} |\n")

    if a.json:
        with open(a.json, "w") as f:
            json.dump({"commit": a.commit, "battery_run": a.what, "headers": headers, "total": total,
                       "untaken": untaken}, f, indent=1)
            f.write("\n")
    unexplained = sum(u["reason"] is None for u in untaken)
    print(f"[coverage] {len(untaken)} untaken sampling-path lines, {unexplained} without a reason"
          + (f" in {a.reasons}" if a.reasons else " (no --reasons file given)"))


if __name__ == "__main__":
    main()
