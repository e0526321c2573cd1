#!/usr/bin/env python3
"""Writes docs/benchmarks.md from benchmarks/benchmarks.md.in and the benchmark outputs
under benchmarks/results/.

usage:
  benchmarks_doc.py [--check]
      Writes docs/benchmarks.md (with --check: compares instead, and exits 1 naming the
      first line that differs).
  benchmarks_doc.py record-gbench GBENCH.json RECORD.json --command CMD [--conditions TEXT]
                    [--date YYYY-MM-DD] --column LABEL=FIELD ...
      Appends the rows of a Google Benchmark output (`--benchmark_out=GBENCH.json`) to a
      record as one new run. FIELD is `name`, `real_time`, `cpu_time` (in the unit the
      benchmark reports, with the unit appended) or a counter's name; a record that
      already has columns must be given the same labels.

The template is Markdown with directives, each alone on its line:
  <!-- table: results/NAME.json -->      a record: {"columns", "runs", "rows"}; each row
                                          names its run, each run its date and command
  <!-- bench: results/A.json ... -->     `tessera bench --json` files, through
                                          bench_table.py (a .command file beside each)
Every table row ends with its run's number; the runs' dates, conditions and commands
follow the table.
"""
import argparse
import datetime
import json
import os
import re
import sys

import bench_table

HERE = os.path.dirname(os.path.abspath(__file__))
TEMPLATE = os.path.join(HERE, "benchmarks.md.in")
DOC = os.path.join(HERE, "..", "docs", "benchmarks.md")
DIRECTIVE = re.compile(r"^<!-- (table|bench): (.+) -->$")
DATE = re.compile(r"^\d{4}-\d{2}-\d{2}")


class RecordError(Exception):
    pass


def load_record(path):
    try:
        with open(path) as f:
            record = json.load(f)
    except (OSError, ValueError) as error:
        raise RecordError("%s: %s" % (path, error))
    for key in ("columns", "runs", "rows"):
        if not isinstance(record.get(key), list):
            raise RecordError("%s: field '%s' is missing or not a list" % (path, key))
    for number, run in enumerate(record["runs"], 1):
        if not DATE.match(str(run.get("date", ""))):
            raise RecordError("%s: runs[%d].date '%s' is not YYYY-MM-DD"
                              % (path, number - 1, run.get("date", "")))
        if not str(run.get("command", "")).strip():
            raise RecordError("%s: runs[%d] has no command" % (path, number - 1))
    for index, row in enumerate(record["rows"]):
        if not 1 <= row.get("run", 0) <= len(record["runs"]):
            raise RecordError("%s: rows[%d].run %s names no run (there are %d)"
                              % (path, index, row.get("run"), len(record["runs"])))
        if len(row.get("cells", [])) != len(record["columns"]):
            raise RecordError("%s: rows[%d] has %d cells for %d columns"
                              % (path, index, len(row.get("cells", [])), len(record["columns"])))
    return record


def record_table(path):
    record = load_record(path)
    columns = record["columns"] + ["run"]
    lines = ["| " + " | ".join(columns) + " |", "| --- " * len(columns) + "|"]
    for row in record["rows"]:
        lines.append("| " + " | ".join(row["cells"] + ["(%d)" % row["run"]]) + " |")
    lines.append("")
    for number, run in enumerate(record["runs"], 1):
        conditions = run.get("conditions", "")
        lines.append("- (%d) %s%s: `%s`" % (number, run["date"],
                                            ", " + conditions if conditions else "",
                                            run["command"]))
    return lines


def render(template=TEMPLATE):
    base = os.path.dirname(template)
    out = []
    with open(template) as f:
        for number, line in enumerate(f.read().split("\n"), 1):
            match = DIRECTIVE.match(line)
            if not match:
                out.append(line)
                continue
            paths = [os.path.join(base, p) for p in match.group(2).split()]
            missing = [p for p in paths if not os.path.exists(p)]
            if missing:
                raise RecordError("%s:%d: %s does not exist" % (template, number, missing[0]))
            if match.group(1) == "table":
                if len(paths) != 1:
                    raise RecordError("%s:%d: a table directive names one record"
                                      % (template, number))
                out.extend(record_table(paths[0]))
            else:
                out.extend(bench_table.table(paths))
    return "\n".join(out)


def gbench_cell(benchmark, field):
    if field == "name":
        return benchmark["name"]
    if field in ("real_time", "cpu_time"):
        return "%.4g %s" % (benchmark[field], benchmark.get("time_unit", "ns"))
    if field not in benchmark:
        raise RecordError("benchmark '%s' has no field or counter '%s'"
                          % (benchmark["name"], field))
    return "%.4g" % benchmark[field]


def record_gbench(args):
    try:
        with open(args.gbench) as f:
            output = json.load(f)
    except (OSError, ValueError) as error:
        raise RecordError("%s: %s" % (args.gbench, error))
    if not isinstance(output.get("benchmarks"), list):
        raise RecordError("%s: not a Google Benchmark JSON output (no 'benchmarks' list)"
                          % args.gbench)
    columns = []
    for spec in args.column:
        label, sep, field = spec.partition("=")
        if not sep or not label or not field:
            raise RecordError("--column '%s': expected LABEL=FIELD" % spec)
        columns.append((label, field))
    record = (load_record(args.record) if os.path.exists(args.record)
              else {"columns": [c[0] for c in columns], "runs": [], "rows": []})
    if record["columns"] != [c[0] for c in columns]:
        raise RecordError("%s: has columns %s, --column gives %s"
                          % (args.record, record["columns"], [c[0] for c in columns]))
    date = args.date or output.get("context", {}).get("date", "")[:10]
    if not DATE.match(date):
        date = datetime.date.today().isoformat()
    record["runs"].append({"date": date, "command": args.command,
                           "conditions": args.conditions})
    run = len(record["runs"])
    benchmarks = [b for b in output["benchmarks"] if b.get("run_type", "iteration") == "iteration"]
    if not benchmarks:
        raise RecordError("%s: holds no benchmark run" % args.gbench)
    for benchmark in benchmarks:
        record["rows"].append({"run": run,
                               "cells": [gbench_cell(benchmark, f) for _, f in columns]})
    with open(args.record, "w") as f:
        json.dump(record, f, indent=1, ensure_ascii=False)
        f.write("\n")
    print("%s: run %d, %d rows" % (args.record, run, len(benchmarks)))


def main(argv):
    if argv and argv[0] == "record-gbench":
        parser = argparse.ArgumentParser(prog="benchmarks_doc.py record-gbench")
        parser.add_argument("gbench")
        parser.add_argument("record")
        parser.add_argument("--command", required=True)
        parser.add_argument("--conditions", default="")
        parser.add_argument("--date", default="")
        parser.add_argument("--column", action="append", required=True)
        record_gbench(parser.parse_args(argv[1:]))
        return 0
    parser = argparse.ArgumentParser(description="Writes docs/benchmarks.md.")
    parser.add_argument("--check", action="store_true")
    parser.add_argument("--template", default=TEMPLATE)
    parser.add_argument("--doc", default=DOC)
    args = parser.parse_args(argv)
    text = render(args.template)
    if not args.check:
        with open(args.doc, "w") as f:
            f.write(text)
        return 0
    with open(args.doc) as f:
        current = f.read()
    if current == text:
        return 0
    old, new = current.split("\n"), text.split("\n")
    line = next((i for i, (a, b) in enumerate(zip(old, new)) if a != b), min(len(old), len(new)))
    print("%s:%d: differs from what benchmarks/benchmarks_doc.py writes; run "
          "`python3 benchmarks/benchmarks_doc.py` (edit benchmarks/benchmarks.md.in or "
          "benchmarks/results/, not the doc)" % (args.doc, line + 1), file=sys.stderr)
    return 1


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except RecordError as error:
        print("benchmarks_doc: %s" % error, file=sys.stderr)
        sys.exit(2)
