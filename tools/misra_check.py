#!/usr/bin/env python3
"""MISRA C:2012 check of firmware/ (cppcheck's misra addon) against the committed deviation
record tests/static/misra_deviations.txt.

Each finding is keyed by rule, file, enclosing function and the line's code (comments and
spacing removed), never by line number, so moving code keeps the record valid. The check fails
if a finding is not in the record (or more findings share a key than recorded), or if a rule
in the record has no reason. Recorded findings no longer reported are listed (the record can be
tightened) but do not fail.

  tools/misra_check.py                 check (what ctest static.misra runs)
  tools/misra_check.py --write-record  regenerate the record from the code, keeping the
                                       reasons of rules already recorded (new rules get
                                       "REASON NEEDED", which fails the check until written)
"""

import collections
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RECORD = os.path.join(ROOT, "tests", "static", "misra_deviations.txt")
NEEDED = "REASON NEEDED"
HEADER = """\
# MISRA C:2012 deviation record of firmware/ (cppcheck misra addon, tools/misra_check.py).
# [reasons]: rule | why the rule is not followed in this code (applies to every finding of the rule).
# [findings]: rule | file | function ("-" outside functions) | findings | code of the line.
# Regenerate after the code changes: tools/misra_check.py --write-record   (then review the diff)
"""


def strip_code(line):
    line = re.sub(r"/\*.*?(\*/|$)", " ", line)
    line = re.sub(r"//.*$", " ", line)
    return " ".join(line.split())[:100].rstrip()


def functions_by_line(lines):
    """Name of the function each line (1-based) lies in, '-' outside: definitions start at
    column 0 and their body's braces are at column 0 (the project's style)."""
    names = ["-"] * (len(lines) + 2)
    current, candidate = None, None
    for n, text in enumerate(lines, start=1):
        if current is None:
            m = re.match(r"^[A-Za-z_][\w\s\*]*?\b(\w+)\s*\(", text)
            if m and not text.rstrip().endswith(";") and not text.startswith(("typedef", "#")):
                candidate = m.group(1)
            if text.startswith("{") and candidate:
                current = candidate
            elif text.strip() and not text.startswith((" ", "\t", "{")) and not m:
                candidate = None if text.rstrip().endswith(";") else candidate
        if current is None and candidate:
            names[n] = candidate  # the definition's own lines
        if current is not None:
            names[n] = current
            if text.startswith("}"):
                current, candidate = None, None
    return names


def findings():
    """Counter of (rule, file, function, code) over firmware/, from a scratch copy (cppcheck
    writes its dump files next to the sources)."""
    scratch = tempfile.mkdtemp(prefix="misra_")
    try:
        shutil.copytree(os.path.join(ROOT, "firmware"), os.path.join(scratch, "firmware"))
        sources = sorted(
            os.path.join("firmware", "src", f)
            for f in os.listdir(os.path.join(scratch, "firmware", "src"))
            if f.endswith(".c")
        )
        run = subprocess.run(
            ["cppcheck", "--addon=misra", "--std=c99", "-Ifirmware/include", "--quiet", "--template={file}:{line}:{id}"]
            + sources,
            cwd=scratch,
            capture_output=True,
            text=True,
            check=False,
        )
        if run.returncode != 0:
            sys.exit(f"misra_check: cppcheck failed ({run.returncode}):\n{run.stderr}")
        found = collections.Counter()
        cache = {}
        for line in run.stderr.splitlines():
            m = re.match(r"^(.*):(\d+):misra-c2012-([\d.]+)$", line.strip())
            if not m:
                if line.strip():
                    sys.exit(f"misra_check: unexpected cppcheck output: {line}")
                continue
            path, number, rule = m.group(1), int(m.group(2)), m.group(3)
            full = os.path.join(scratch, path)
            if full not in cache:
                with open(full, encoding="utf-8") as f:
                    text = f.read().splitlines()
                cache[full] = (text, functions_by_line(text))
            text, names = cache[full]
            found[(rule, os.path.basename(path), names[number], strip_code(text[number - 1]))] += 1
        return found
    finally:
        shutil.rmtree(scratch)


def read_record():
    reasons, recorded, section = {}, collections.Counter(), None
    if not os.path.exists(RECORD):
        return reasons, recorded
    with open(RECORD, encoding="utf-8") as f:
        for raw in f:
            line = raw.rstrip("\n")
            if not line.strip() or line.startswith("#"):
                continue
            if line in ("[reasons]", "[findings]"):
                section = line
                continue
            parts = [p.strip() for p in line.split("|", 1 if section == "[reasons]" else 4)]
            if section == "[reasons]" and len(parts) == 2:
                reasons[parts[0]] = parts[1]
            elif section == "[findings]" and len(parts) == 5:
                recorded[(parts[0], parts[1], parts[2], parts[4])] += int(parts[3])
            else:
                sys.exit(f"misra_check: malformed line in the record: {line}")
    return reasons, recorded


def rule_key(rule):
    return tuple(int(x) for x in rule.split("."))


def main():
    if shutil.which("cppcheck") is None:
        print("misra_check: cppcheck not installed (tools/install_deps.sh installs it): skipped")
        return 77
    found = findings()
    reasons, recorded = read_record()
    if "--write-record" in sys.argv[1:]:
        rules = sorted({k[0] for k in found}, key=rule_key)
        with open(RECORD, "w", encoding="utf-8") as f:
            f.write(HEADER + "\n[reasons]\n")
            for rule in rules:
                f.write(f"{rule} | {reasons.get(rule, NEEDED)}\n")
            f.write("\n[findings]\n")
            for key in sorted(found, key=lambda k: (rule_key(k[0]), k[1], k[2], k[3])):
                f.write(f"{key[0]} | {key[1]} | {key[2]} | {found[key]} | {key[3]}\n")
        print(
            f"misra_check: wrote {os.path.relpath(RECORD, ROOT)}: {sum(found.values())} findings, "
            f"{len(found)} keys, {len(rules)} rules"
        )
        return 0
    failures = []
    for key, count in sorted(found.items()):
        if count > recorded.get(key, 0):
            failures.append(
                f"  rule {key[0]} in {key[1]}, {key[2]}: {count} finding(s), {recorded.get(key, 0)} recorded: {key[3]}"
            )
    for rule in sorted({k[0] for k in found}, key=rule_key):
        if reasons.get(rule, NEEDED) == NEEDED:
            failures.append(f"  rule {rule}: no reason in the record")
    stale = [k for k in recorded if recorded[k] > found.get(k, 0)]
    per_rule = collections.Counter()
    for key, count in found.items():
        per_rule[key[0]] += count
    print(
        f"misra_check: {sum(found.values())} findings in {len(per_rule)} rules: "
        + ", ".join(f"{r}: {per_rule[r]}" for r in sorted(per_rule, key=rule_key))
    )
    if stale:
        print(
            f"misra_check: {len(stale)} recorded key(s) no longer (or less often) found; "
            "tools/misra_check.py --write-record tightens the record"
        )
    if failures:
        print("misra_check: findings outside the deviation record " + os.path.relpath(RECORD, ROOT) + ":")
        print("\n".join(failures))
        return 1
    print("misra_check: every finding is a recorded deviation")
    return 0


if __name__ == "__main__":
    sys.exit(main())
