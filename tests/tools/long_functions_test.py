#!/usr/bin/env python3
"""The scanner of tools/long_functions.py on sources written here, whose functions' lengths are
known by construction (issue 46, item 5). Standard library only: python3 -m unittest."""
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, 'tools'))
import long_functions  # noqa: E402


def body(lines):
    """`lines` statements, one a line."""
    return ''.join(f'  x += {k};\n' for k in range(lines))


class ScannerTest(unittest.TestCase):
    def lengths(self, text):
        return {name: last - first + 1 for name, first, last in long_functions.functions(text)}

    def test_counts_from_the_name_to_the_closing_brace(self):
        text = 'int f(int x) {\n' + body(5) + '  return x;\n}\n'
        self.assertEqual(self.lengths(text), {'f': 8})

    def test_methods_in_namespaces_and_classes_are_found(self):
        text = ('namespace a::b {\nclass C {\n public:\n  void m() {\n' + body(3) + '  }\n};\n'
                'void C::n(int y) const {\n' + body(2) + '}\n}  // namespace a::b\n')
        self.assertEqual(self.lengths(text), {'m': 5, 'C::n': 4})

    def test_braces_in_comments_strings_and_raw_strings_do_not_count(self):
        text = ('void f() {\n  // }\n  /* } { */\n  const char* s = "}";\n  char c = \'}\';\n'
                '  const char* r = R"x(})x";\n}\nvoid g() {\n}\n')
        self.assertEqual(self.lengths(text), {'f': 7, 'g': 2})

    def test_lambdas_control_blocks_and_local_classes_count_toward_their_function(self):
        text = ('void f() {\n  auto l = [](int a) {\n    return a;\n  };\n  if (true) {\n  }\n'
                '  struct Local { int m() { return 1; } };\n}\n')
        self.assertEqual(self.lengths(text), {'f': 8})

    def test_classes_enums_and_initialisers_are_not_functions(self):
        text = ('struct S {\n  int a = 1;\n};\nenum class E { kA, kB };\n'
                'const int table[] = {1, 2, 3};\nS s{};\n')
        self.assertEqual(self.lengths(text), {})

    def test_the_command_prints_a_function_over_the_limit_and_exits_1(self):
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, 'long.cc')
            with open(path, 'w') as f:
                f.write('void Short() {\n' + body(98) + '}\n')    # 100 lines: within the limit
                f.write('void Long() {\n' + body(99) + '}\n')     # 101 lines: over it
            run = subprocess.run([sys.executable, os.path.join(ROOT, 'tools', 'long_functions.py'),
                                  path], capture_output=True, text=True)
            self.assertEqual(run.returncode, 1, run.stderr)
            self.assertEqual(run.stdout.splitlines(), [f'{os.path.relpath(path, ROOT)}:101: '
                                                       '101 lines: Long'])


if __name__ == '__main__':
    unittest.main()
