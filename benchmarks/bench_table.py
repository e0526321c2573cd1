#!/usr/bin/env python3
"""Turns `tessera bench --json` files into the Markdown table of docs/benchmarks.md.

usage: bench_table.py BENCH.json...

Each BENCH.json may have a BENCH.command beside it (benchmarks/shared_sets_vs_colmap.sh
writes one): its first line the UTC date the bench started, the rest the command. One
table row per bench row: set (the images folder's parent), row, mapper, seconds per
stage, registered images, mean position and rotation errors, and the row's total time
(map time where COLMAP mapped a Tessera row's matches, --colmap-mapper-only; a row that
started from another's features is charged that row's extraction seconds) and
position error as a share of the same bench's COLMAP 4 global row (COLMAP's rows
are named colmap-<version>-global / -incremental). Under the table, each bench's date
and command, numbered as the rows' `run` column.
"""
import json
import os
import sys


def fmt(value, digits):
    return "-" if value is None else "%.*f" % (digits, value)


def mapper_of(row):
    plugins = row["plugins"]
    if plugins.startswith("COLMAP"):
        return plugins.split(":")[0] + (" global" if row["manifest"].endswith("-global")
                                        else " incremental")
    used = [p["plugin"] for p in row.get("plugins_used", []) if p["slot"] == "mapper"]
    return "Tessera " + (used[0] if used else "?")


def share(value, reference):
    if value is None or not reference:
        return "-"
    return "%.2f" % (value / reference)


def table(files):
    """The table's lines, then a blank line and one line per bench (its date and command)."""
    lines = ["| set | row | mapper | extract s | match s | map s | total s | registered | "
             "position error | % of extent | rotation deg | time / COLMAP 4 global | "
             "position error / COLMAP 4 global | run |",
             "| --- " * 14 + "|"]
    notes = []
    for number, path in enumerate(files, 1):
        bench = json.load(open(path))
        images = bench["images"].rstrip("/")
        name = os.path.basename(os.path.dirname(images)) or images
        reference = next((r for r in bench["rows"] if r["manifest"].startswith("colmap-4")
                          and r["manifest"].endswith("-global") and r["exit_code"] == 0), None)
        # Map time alone where COLMAP mapped a Tessera row's matches (--colmap-mapper-only).
        key = "map_seconds" if reference and reference.get("matches_of") else "total_seconds"
        by_name = {r["manifest"]: r for r in bench["rows"]}
        for row in bench["rows"]:
            extract = fmt(row["extract_seconds"], 1)
            seconds = row[key]
            shared = row.get("extract_shared_with") or ""
            if shared and key == "total_seconds" and seconds is not None:
                # Charged the extraction it started from, as if it had run alone.
                extract += " (features of %s)" % shared
                seconds += by_name[shared]["extract_seconds"] or 0
            registered = "%d/%d" % (row["num_registered"], row["num_images"])
            if row["exit_code"] != 0:
                registered += " (exit %d)" % row["exit_code"]
            lines.append("| " + " | ".join([
                name, row["manifest"], mapper_of(row), extract,
                fmt(row["match_seconds"], 1), fmt(row["map_seconds"], 1),
                fmt(row["total_seconds"], 1), registered, fmt(row["position_error_mean"], 5),
                fmt(None if row["position_error_mean_relative"] is None
                    else 100 * row["position_error_mean_relative"], 3),
                fmt(row["rotation_error_mean_deg"], 3),
                share(seconds, reference and reference[key]),
                share(row["position_error_mean"], reference and reference["position_error_mean"]),
                "(%d)" % number]) + " |")
        command_file = os.path.splitext(path)[0] + ".command"
        if os.path.exists(command_file):
            date, _, command = open(command_file).read().strip().partition("\n")
            notes.append("(%d) %s: `%s`" % (number, date, command.strip()))
        else:
            notes.append("(%d) %s (no command recorded)" % (number, path))
    return lines + [""] + ["- " + note for note in notes]


def main(files):
    print("\n".join(table(files)))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
