#!/usr/bin/env python3
"""No circles between the source files of one library: from nm of each static library (each
member object), an edge A -> B when object A uses (U) a global symbol that object B defines
(T, D, B, R, C, W, ...). Every strongly connected component of more than one file is a cycle;
each is reported by its files and the symbols that make each of its edges. Exit 1 if any cycle
is not allowed, 0 otherwise. Standard library only.

  tools/check_file_cycles.py [--nm NM] [--allow a.c:b.c ...] LIBRARY.a ...

--allow a.c:b.c tolerates a cycle of exactly those files (a known one, waiting for its fix);
the same files with another file joined fail, and an allowance whose cycle is gone fails too
(remove it). What ctest static.file_cycles runs on the host build's libraries.
"""

import argparse
import os
import re
import subprocess
import sys

# nm -A -P (POSIX format, file name on every line): "lib.a[member.o]: name type value size" or
# "member.o: name type ..." for a lone object.
_LINE = re.compile(r"^(?P<file>.*?): (?P<name>\S+) (?P<type>[A-Za-z?]) ?")
_MEMBER = re.compile(r"^.*\[(?P<member>[^\]]+)\]$")


def source_name(obj):
    """The source file an object was built from: pmstep_config.c.o -> pmstep_config.c."""
    base = os.path.basename(obj)
    return base[:-2] if base.endswith(".o") else base


def parse_nm(text):
    """{file: (defined, undefined)} from the text of nm -A -P over one library: the global
    symbols each member defines and those it uses undefined."""
    table = {}
    for line in text.splitlines():
        match = _LINE.match(line)
        if not match:
            continue
        where = match.group("file")
        member = _MEMBER.match(where)
        name = source_name(member.group("member") if member else where)
        defined, undefined = table.setdefault(name, (set(), set()))
        kind = match.group("type")
        if kind in "Uvw":
            # undefined, or weak and not defined in this object (v, w)
            undefined.add(match.group("name"))
        elif kind.isupper():
            defined.add(match.group("name"))
        # lower case otherwise: a local symbol, no edge
    return table


def edges(table):
    """{(a, b): sorted symbols} for every file a using a symbol file b defines (a != b)."""
    definer = {}
    for name, (defined, _) in table.items():
        for symbol in defined:
            definer.setdefault(symbol, set()).add(name)
    result = {}
    for name, (_, undefined) in table.items():
        for symbol in undefined:
            for target in definer.get(symbol, ()):
                if target != name:
                    result.setdefault((name, target), set()).add(symbol)
    return {edge: sorted(symbols) for edge, symbols in result.items()}


def components(nodes, graph_edges):
    """The strongly connected components of more than one node (Tarjan), each a sorted list,
    in sorted order."""
    successors = {node: [] for node in nodes}
    for a, b in graph_edges:
        successors.setdefault(a, []).append(b)
        successors.setdefault(b, [])
    index, low, on_stack, stack, found = {}, {}, set(), [], []
    counter = [0]

    def visit(root):
        # iterative depth-first search: (node, iterator over its successors)
        work = [(root, iter(sorted(successors[root])))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            advanced = False
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter[0]
                    counter[0] += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(successors[child]))))
                    advanced = True
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            if advanced:
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))

    for node in sorted(successors):
        if node not in index:
            visit(node)
    return sorted(found)


def cycles(table):
    """[(files, {(a, b): symbols})]: each cycle of a library's symbol table with its edges."""
    graph = edges(table)
    result = []
    for component in components(table.keys(), graph):
        members = set(component)
        inner = {edge: symbols for edge, symbols in sorted(graph.items()) if edge[0] in members and edge[1] in members}
        result.append((component, inner))
    return result


def describe(library, files, inner):
    lines = [f"{library}: cycle between {', '.join(files)}"]
    for (a, b), symbols in inner.items():
        lines.append(f"  {a} -> {b}: {', '.join(symbols)}")
    return "\n".join(lines)


def check(libraries, allowed, out=sys.stdout):
    """Reports the cycles of {library: table}; returns the exit status (allowed: frozensets)."""
    status = 0
    seen = set()
    for library, table in libraries.items():
        for files, inner in cycles(table):
            key = frozenset(files)
            if key in allowed:
                seen.add(key)
                print("allowed " + describe(library, files, inner), file=out)
            else:
                status = 1
                print(describe(library, files, inner), file=out)
    for key in sorted(allowed - seen, key=sorted):
        status = 1
        print(f"--allow {':'.join(sorted(key))}: no such cycle any more; remove the allowance", file=out)
    if status == 0:
        print(
            f"no cycle between the source files of {len(libraries)} libraries"
            + (f" ({len(seen)} allowed)" if seen else ""),
            file=out,
        )
    return status


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--nm", default="nm", help="the nm to run (CMake's CMAKE_NM)")
    parser.add_argument(
        "--allow", action="append", default=[], metavar="A.c:B.c", help="tolerate a cycle of exactly these files"
    )
    parser.add_argument("libraries", nargs="+", help="static libraries (.a) or objects")
    args = parser.parse_args(argv)
    allowed = {frozenset(entry.split(":")) for entry in args.allow}
    libraries = {}
    for library in args.libraries:
        run = subprocess.run([args.nm, "-A", "-P", "-g", library], capture_output=True, text=True, check=False)
        if run.returncode != 0:
            print(f"{args.nm} {library} failed:\n{run.stderr}", file=sys.stderr)
            return 2
        libraries[os.path.basename(library)] = parse_nm(run.stdout)
    return check(libraries, allowed)


if __name__ == "__main__":
    sys.exit(main())
