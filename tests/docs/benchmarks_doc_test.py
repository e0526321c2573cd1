#!/usr/bin/env python3
"""docs/benchmarks.md is what benchmarks/benchmarks_doc.py writes, every table row names a
run with a date and a command, and a Google Benchmark's own output becomes a table.

usage: benchmarks_doc_test.py SOURCE_DIR [VIEW_GRAPH_BENCHMARK]
With the benchmark binary, the record-gbench test runs it for real (one case, briefly)
and turns its `--benchmark_out` file into a table.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

SOURCE = os.path.abspath(sys.argv[1]) if len(sys.argv) > 1 else os.getcwd()
BENCHMARK = sys.argv[2] if len(sys.argv) > 2 else ""
SCRIPT = os.path.join(SOURCE, "benchmarks", "benchmarks_doc.py")


def run(*args, cwd=None):
    return subprocess.run([sys.executable, SCRIPT] + list(args), capture_output=True,
                          text=True, cwd=cwd)


class BenchmarksDocTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="benchmarks_doc_test.")

    def tearDown(self):
        shutil.rmtree(self.dir)

    def write(self, name, content):
        path = os.path.join(self.dir, name)
        with open(path, "w") as f:
            f.write(content if isinstance(content, str) else json.dumps(content))
        return path

    def render(self, record):
        self.write("r.json", record)
        template = self.write("t.md.in", "# T\n\n<!-- table: r.json -->\n")
        doc = os.path.join(self.dir, "doc.md")
        return run("--template", template, "--doc", doc), doc

    def test_the_committed_page_is_what_the_script_writes(self):
        result = run("--check")
        self.assertEqual(result.returncode, 0, result.stderr)

    def test_every_record_row_names_a_dated_run_with_a_command(self):
        with open(os.path.join(SOURCE, "benchmarks", "benchmarks.md.in")) as f:
            template = f.read()
        tables = [line.split("table: ")[1].split(" -->")[0]
                  for line in template.split("\n") if line.startswith("<!-- table: ")]
        self.assertGreater(len(tables), 20)
        for table in tables:
            with open(os.path.join(SOURCE, "benchmarks", table)) as f:
                record = json.load(f)
            for row in record["rows"]:
                run_of_row = record["runs"][row["run"] - 1]
                self.assertRegex(run_of_row["date"], r"^\d{4}-\d{2}-\d{2}", table)
                self.assertTrue(run_of_row["command"].strip(), table)

    def test_a_stale_page_fails_the_check_and_names_the_line(self):
        result, doc = self.render({"columns": ["a"], "runs": [
            {"date": "2026-12-06", "command": "x --y"}], "rows": [{"run": 1, "cells": ["1"]}]})
        self.assertEqual(result.returncode, 0, result.stderr)
        with open(doc) as f:
            text = f.read()
        self.assertIn("| 1 | (1) |", text)
        self.assertIn("- (1) 2026-12-06: `x --y`", text)
        with open(doc, "w") as f:
            f.write(text.replace("| 1 | (1) |", "| 2 | (1) |"))
        check = run("--check", "--template", os.path.join(self.dir, "t.md.in"), "--doc", doc)
        self.assertEqual(check.returncode, 1)
        self.assertIn("doc.md:5: differs", check.stderr)

    def test_a_row_without_a_dated_run_or_command_is_refused(self):
        cases = [
            ({"columns": ["a"], "runs": [{"date": "", "command": "x"}],
              "rows": [{"run": 1, "cells": ["1"]}]}, "runs[0].date '' is not YYYY-MM-DD"),
            ({"columns": ["a"], "runs": [{"date": "2026-12-06", "command": " "}],
              "rows": [{"run": 1, "cells": ["1"]}]}, "runs[0] has no command"),
            ({"columns": ["a"], "runs": [{"date": "2026-12-06", "command": "x"}],
              "rows": [{"run": 2, "cells": ["1"]}]}, "rows[0].run 2 names no run"),
            ({"columns": ["a", "b"], "runs": [{"date": "2026-12-06", "command": "x"}],
              "rows": [{"run": 1, "cells": ["1"]}]}, "rows[0] has 1 cells for 2 columns"),
        ]
        for record, message in cases:
            result, _ = self.render(record)
            self.assertEqual(result.returncode, 2, message)
            self.assertIn("r.json: " + message, result.stderr)

    def test_a_google_benchmark_output_becomes_a_table(self):
        if BENCHMARK:
            out = os.path.join(self.dir, "out.json")
            subprocess.run([BENCHMARK, "--benchmark_filter=/200/5/1/",
                            "--benchmark_min_time=0.01", "--benchmark_out=" + out,
                            "--benchmark_out_format=json"], check=True, capture_output=True)
        else:  # The shape of a real output, for a run without the benchmarks built.
            out = self.write("out.json", {"context": {"date": "2026-12-06T08:10:04+00:00"},
                                          "benchmarks": [{
                                              "name": "BM_ViewGraphBuildUncalibrated/200/5/1/real_time",
                                              "run_type": "iteration", "real_time": 379.08,
                                              "cpu_time": 67.67, "time_unit": "ms",
                                              "per_pair": 0.0019951, "pairs": 190.0}]})
        record = os.path.join(self.dir, "r.json")
        result = run("record-gbench", out, record, "--command", "view_graph_benchmark",
                     "--column", "case=name", "--column", "s per pair=per_pair",
                     "--column", "pairs=pairs")
        self.assertEqual(result.returncode, 0, result.stderr)
        with open(record) as f:
            data = json.load(f)
        self.assertEqual(data["columns"], ["case", "s per pair", "pairs"])
        self.assertEqual(len(data["rows"]), 1)
        self.assertEqual(data["rows"][0]["cells"][0],
                         "BM_ViewGraphBuildUncalibrated/200/5/1/real_time")
        self.assertEqual(data["rows"][0]["cells"][2], "190")
        self.assertRegex(data["runs"][0]["date"], r"^\d{4}-\d{2}-\d{2}$")
        template = self.write("t.md.in", "<!-- table: r.json -->\n")
        rendered = run("--template", template, "--doc", os.path.join(self.dir, "doc.md"))
        self.assertEqual(rendered.returncode, 0, rendered.stderr)
        # A second run with other columns is refused rather than mixed into the table.
        again = run("record-gbench", out, record, "--command", "x", "--column", "case=name")
        self.assertEqual(again.returncode, 2)
        self.assertIn("has columns", again.stderr)
        missing = run("record-gbench", out, os.path.join(self.dir, "n.json"), "--command",
                      "x", "--column", "v=no_such_counter")
        self.assertEqual(missing.returncode, 2)
        self.assertIn("has no field or counter 'no_such_counter'", missing.stderr)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
