#!/usr/bin/env python3
"""Tests of scripts/check-code-health.py's function finder and path checker on tricky C++ and text.
Run: python3 scripts/check_code_health_test.py (scripts/test.sh runs it before the check itself)."""
import importlib.util
import pathlib
import tempfile
import unittest

HERE = pathlib.Path(__file__).resolve().parent
spec = importlib.util.spec_from_file_location("check_code_health", HERE / "check-code-health.py")
chk = importlib.util.module_from_spec(spec)
spec.loader.exec_module(chk)


def body(n):
    return "".join(f"  x += {i};\n" for i in range(n))


class FunctionsTest(unittest.TestCase):
    def lengths(self, code):
        with tempfile.TemporaryDirectory() as d:
            root = pathlib.Path(d)
            (root / "f.cc").write_text(code)
            old, chk.ROOT = chk.ROOT, root
            try:
                return {name: lines for name, _, lines in chk.functions("f.cc")}
            finally:
                chk.ROOT = old

    def test_plain_function_counts_brace_to_brace(self):
        self.assertEqual(self.lengths("int f(int x) {\n" + body(3) + "}\n"), {"f": 5})

    def test_lambdas_and_blocks_count_in_the_enclosing_function(self):
        code = "void g() {\n  auto l = [&](int a) {\n" + body(4) + "  };\n  if (true) {\n  }\n}\n"
        self.assertEqual(self.lengths(code), {"g": 10})

    def test_braced_member_initialiser_does_not_hide_the_constructor(self):
        code = "Foo::Foo(int x) : a_(x), b_{x, 2} {\n" + body(200) + "}\n"
        self.assertEqual(self.lengths(code), {"Foo::Foo": 202})

    def test_requires_macro_try_and_trailing_return(self):
        code = ("template <class T>\nauto f(T t) -> int requires C<T> {\n" + body(2) + "}\n"
                "int g() VC_NOEXCEPT {\n" + body(2) + "}\n"
                "int h() try {\n" + body(2) + "} catch (...) {\n  return 0;\n}\n")
        lengths = self.lengths(code)
        self.assertEqual(lengths["f"], 4)
        self.assertEqual(lengths["g"], 4)
        self.assertEqual(lengths["h"], 4)  # the handler is a block after the body

    def test_lambda_at_namespace_scope_without_parameters(self):
        self.assertEqual(list(self.lengths("const int k = [] {\n" + body(160) + "}();\n").values()), [162])

    def test_literals_hide_their_braces(self):
        code = ("char a = L'{';\nconst char* s = u8\"{{\";\nauto r = LR\"x({)x\";\nint n = 1'000;\n"
                "int f() {\n" + body(160) + "}\n")
        self.assertEqual(self.lengths(code), {"f": 162})

    def test_classes_namespaces_and_aggregates_are_not_functions(self):
        code = "namespace a {\nclass B : public C {\n public:\n  int f() const { return 1; }\n};\n}\n"
        code += "const Foo kFoo = Foo{1, 2};\nenum class E : int { kA };\n"
        self.assertEqual(self.lengths(code), {"f": 1})


class PathsTest(unittest.TestCase):
    files = {"core/plan/src/route.cc", "docs/PLANNING.md", "tests/core/plan/route_test.cc"}
    dirs = {"core", "core/plan", "core/plan/src", "docs", "tests", "tests/core", "tests/core/plan"}

    def test_existing_paths_and_globs(self):
        for ref in ("core/plan/src/route.cc", "docs/PLANNING.md", "tests/core/*/*_test.cc", "core/plan/"):
            self.assertTrue(chk.path_exists(ref, self.files, self.dirs), ref)

    def test_missing_paths(self):
        for ref in ("core/src/route.cc", "tests/core/*_test.cc", "docs/NOPE.md"):
            self.assertFalse(chk.path_exists(ref, self.files, self.dirs), ref)

    def test_paths_after_dot_prefixes_are_found(self):
        self.assertEqual(chk.PATH.findall("see ./docs/PLANNING.md and `core/x.cc`"), ["docs/PLANNING.md", "core/x.cc"])
        self.assertEqual(chk.PATH.findall("$BIN/server/vc-server build/release/core/vc-synth"), [])


if __name__ == "__main__":
    unittest.main(verbosity=1)
