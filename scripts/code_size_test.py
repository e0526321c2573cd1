#!/usr/bin/env python3
"""Tests of code_size.py's function finder on small sources of this codebase's style."""

import os
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import code_size  # noqa: E402


def functions_of(source):
    """[(name, first line, last line)] of the functions code_size.py finds in source."""
    code = code_size.strip_code(source)
    return [(name, code.count("\n", 0, start) + 1, code.count("\n", 0, end - 1) + 1)
            for name, start, end in code_size.find_functions(code)]


class FindFunctionsTest(unittest.TestCase):

    def test_lambdas_and_blocks_belong_to_their_function(self):
        source = """namespace tessera {
namespace {

int Sum(const std::vector<int>& values) {
  const auto add = [&](int x) {
    return x + 1;
  };
  int sum = 0;
  for (int v : values) {
    sum += add(v);
  }
  return sum;
}

}  // namespace

void Later() {}
}  // namespace tessera
"""
        self.assertEqual(functions_of(source), [("Sum", 4, 13), ("Later", 17, 17)])

    def test_braces_in_comments_and_literals_are_ignored(self):
        source = """// A comment { with a brace
const char* Text() {
  /* } */
  const char c = '}';
  const std::string raw = R"json({"a": {"b": 1}})json";
  return "}}";
}
int Next() { return 1'000; }
"""
        self.assertEqual(functions_of(source), [("Text", 2, 7), ("Next", 8, 8)])

    def test_classes_initializer_lists_and_default_arguments(self):
        source = """struct Options {
  Options(int a = {}, std::vector<int> b = {})
      : a_(a),
        b_{std::move(b)} {
    Check();
  }
 public:
  bool operator==(const Options& other) const { return a_ == other.a_; }
  explicit operator bool() const { return a_ != 0; }
  int a_;
  std::vector<int> b_;
};
bool Declared(const Control& control = {});
template <typename T>
T Identity(T value) {
  return value;
}
"""
        self.assertEqual(functions_of(source), [("Options", 2, 6), ("operator==", 8, 8),
                                                ("operator bool", 9, 9), ("Identity", 14, 17)])

    def test_tables_and_enums_are_not_functions(self):
        source = """enum class Kind { kA, kB };
constexpr Entry kEntries[] = {
    {"a", 1},
    {"b", 2},
};
const std::map<std::string, int> kNames = {{"a", Make(1)}};
extern "C" {
void Exported() {}
}
void Qualified::Name::Method() const {}
"""
        self.assertEqual(functions_of(source), [("Exported", 8, 8),
                                                ("Qualified::Name::Method", 10, 10)])


class CommandLineTest(unittest.TestCase):

    def run_script(self, root, *args):
        script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "code_size.py")
        return subprocess.run([sys.executable, script, "--root", root, *args],
                              capture_output=True, text=True)

    def write(self, root, path, text):
        os.makedirs(os.path.dirname(os.path.join(root, path)), exist_ok=True)
        with open(os.path.join(root, path), "w") as f:
            f.write(text)

    def test_limits_list_each_violation_and_exclusions_and_tests_are_skipped(self):
        long_body = "void Long() {\n" + "  Step();\n" * 10 + "}\n"
        with tempfile.TemporaryDirectory() as root:
            self.write(root, "host/src/a/long.cc", long_body)
            self.write(root, "host/src/b/other.cc", long_body)
            self.write(root, "host/src/a/long_test.cc", long_body * 5)
            self.write(root, "plugins/p/fuzz/fuzz_target.cc", long_body * 5)

            within = self.run_script(root, "--max-function", "12", "--max-file", "12")
            self.assertEqual(within.returncode, 0, within.stdout + within.stderr)
            self.assertIn("12  host/src/a/long.cc:1  Long", within.stdout)
            self.assertNotIn("long_test.cc", within.stdout)
            self.assertNotIn("fuzz", within.stdout)

            over = self.run_script(root, "--max-function", "11", "--max-file", "12")
            self.assertEqual(over.returncode, 1)
            self.assertIn("host/src/a/long.cc:1: function Long has 12 lines (max 11)", over.stdout)
            self.assertIn("host/src/b/other.cc:1: function Long has 12 lines (max 11)", over.stdout)

            excluded = self.run_script(root, "--max-function", "11", "--exclude", "host/src/a",
                                       "--exclude", "host/src/b/other.cc")
            self.assertEqual(excluded.returncode, 0, excluded.stdout)

            file_over = self.run_script(root, "--max-file", "11")
            self.assertEqual(file_over.returncode, 1)
            self.assertIn("host/src/a/long.cc: file has 12 lines (max 11)", file_over.stdout)

    def test_unbalanced_braces_are_an_error_not_a_guess(self):
        with tempfile.TemporaryDirectory() as root:
            self.write(root, "host/src/a/broken.cc", "void F() {\n")
            result = self.run_script(root)
            self.assertEqual(result.returncode, 2)
            self.assertIn("host/src/a/broken.cc: braces do not balance", result.stderr)


if __name__ == "__main__":
    unittest.main()
