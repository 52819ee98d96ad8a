"""Tests of tools/check_file_cycles.py (python3 -m unittest test_check_file_cycles): the nm
reading and the cycle finding on made-up symbol tables, with and without a cycle, and the
allowance of a known one. Standard library only; nm is not run."""

import io
import unittest

import tools_path  # noqa: F401  (tools/ on the import path)
import check_file_cycles as cfc

NM_TEXT = """\
libx.a[a.c.o]: helper_b U
libx.a[a.c.o]: __asan_init U
libx.a[a.c.o]: api_a T 0000000000000000 0000000000000010
libx.a[a.c.o]: table_a R 0000000000000000 0000000000000040
libx.a[b.c.o]: api_a U
libx.a[b.c.o]: helper_b T 0000000000000000 0000000000000010
libx.a[b.c.o]: state_b B 0000000000000000 0000000000000004
libx.a[c.c.o]: state_b U
libx.a[c.c.o]: weak_hook w
libx.a[c.c.o]: api_c T 0000000000000000 0000000000000010
libx.a[d.c.o]: weak_hook W 0000000000000000 0000000000000010
"""


def table(**files):
    """{file: (defined, undefined)} from keyword arguments file=("def1 def2", "undef1 ...")."""
    return {name + ".c": (set(defined.split()), set(undefined.split())) for name, (defined, undefined) in files.items()}


class ParseNm(unittest.TestCase):
    def test_members_and_kinds(self):
        parsed = cfc.parse_nm(NM_TEXT)
        self.assertEqual(sorted(parsed), ["a.c", "b.c", "c.c", "d.c"])
        self.assertEqual(parsed["a.c"], ({"api_a", "table_a"}, {"helper_b", "__asan_init"}))
        self.assertEqual(parsed["b.c"][0], {"helper_b", "state_b"})
        self.assertEqual(parsed["c.c"][1], {"state_b", "weak_hook"})
        self.assertEqual(parsed["d.c"][0], {"weak_hook"})

    def test_lone_object(self):
        parsed = cfc.parse_nm("build/dir/e.c.o: api_e T 0 10\n")
        self.assertEqual(parsed, {"e.c": ({"api_e"}, set())})

    def test_edges_and_cycle_of_nm_text(self):
        parsed = cfc.parse_nm(NM_TEXT)
        self.assertEqual(
            cfc.edges(parsed),
            {
                ("a.c", "b.c"): ["helper_b"],
                ("b.c", "a.c"): ["api_a"],
                ("c.c", "b.c"): ["state_b"],
                ("c.c", "d.c"): ["weak_hook"],
            },
        )
        self.assertEqual(
            cfc.cycles(parsed), [(["a.c", "b.c"], {("a.c", "b.c"): ["helper_b"], ("b.c", "a.c"): ["api_a"]})]
        )


class Cycles(unittest.TestCase):
    def test_none(self):
        # a -> b -> c, a -> c: layered, no cycle
        symbols = table(a=("fa", "fb fc"), b=("fb", "fc"), c=("fc", "memcpy"))
        self.assertEqual(cfc.cycles(symbols), [])
        out = io.StringIO()
        self.assertEqual(cfc.check({"liba.a": symbols}, set(), out), 0)
        self.assertIn("no cycle", out.getvalue())

    def test_three_files_and_a_separate_pair(self):
        # a -> b -> c -> a, and d <-> e; f uses a but is in no cycle
        symbols = table(
            a=("fa", "fb"), b=("fb", "fc"), c=("fc", "fa"), d=("fd", "fe"), e=("fe", "fd"), f=("ff", "fa fd")
        )
        found = cfc.cycles(symbols)
        self.assertEqual([files for files, _ in found], [["a.c", "b.c", "c.c"], ["d.c", "e.c"]])
        self.assertEqual(found[0][1], {("a.c", "b.c"): ["fb"], ("b.c", "c.c"): ["fc"], ("c.c", "a.c"): ["fa"]})
        out = io.StringIO()
        self.assertEqual(cfc.check({"liba.a": symbols}, set(), out), 1)
        self.assertIn("liba.a: cycle between a.c, b.c, c.c\n  a.c -> b.c: fb\n", out.getvalue())
        self.assertIn("liba.a: cycle between d.c, e.c\n  d.c -> e.c: fe\n  e.c -> d.c: fd", out.getvalue())

    def test_cycle_only_within_one_library(self):
        # the same names in two libraries: each library's graph is its own
        out = io.StringIO()
        self.assertEqual(cfc.check({"liba.a": table(a=("fa", "fb")), "libb.a": table(b=("fb", "fa"))}, set(), out), 0)

    def test_allowance_exact(self):
        pair = table(a=("fa", "fb"), b=("fb", "fa"), c=("fc", "fa"))
        out = io.StringIO()
        self.assertEqual(cfc.check({"liba.a": pair}, {frozenset({"a.c", "b.c"})}, out), 0)
        self.assertIn("allowed liba.a: cycle between a.c, b.c", out.getvalue())
        # a third file joining the allowed pair is a new cycle
        grown = table(a=("fa", "fb"), b=("fb", "fa fc"), c=("fc", "fa"))
        self.assertEqual(cfc.check({"liba.a": grown}, {frozenset({"a.c", "b.c"})}, io.StringIO()), 1)

    def test_allowance_gone(self):
        out = io.StringIO()
        self.assertEqual(
            cfc.check({"liba.a": table(a=("fa", "fb"), b=("fb", ""))}, {frozenset({"a.c", "b.c"})}, out), 1
        )
        self.assertIn("--allow a.c:b.c: no such cycle any more", out.getvalue())

    def test_long_chain(self):
        # deep graphs do not hit the recursion limit: a ring of 5000 files
        count = 5000
        ring = {f"f{i}.c": ({f"s{i}"}, {f"s{(i + 1) % count}"}) for i in range(count)}
        found = cfc.cycles(ring)
        self.assertEqual(len(found), 1)
        self.assertEqual(len(found[0][0]), count)


if __name__ == "__main__":
    unittest.main()
