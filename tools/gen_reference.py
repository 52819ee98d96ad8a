#!/usr/bin/env python3
"""Writes the reference pages of the documentation site from the code's own tables.

Usage:
  tools/gen_reference.py [--out docs/reference] [--sil PATH]

Pages (in --out, default docs/reference of this tree):
  configuration.md     every field of pmstep_config_t (firmware/include/pmstep/pmstep_types.h): the
                       console's id and access (table[] of firmware/console/src/pmstep_console_config.c),
                       the C type, the unit (the name's suffix: UNIT_SUFFIXES), the meaning (the field's
                       doc comment) and the range init validates: the sign of sign_rules[]
                       (firmware/src/pmstep_config.c) and every status code of init whose cause (its doc
                       comment in pmstep_status_t) names the field (FIELD_PHRASES). Then the STEP/DIR
                       settings the console stores with them (pmstep_stepdir_settings_t of
                       firmware/console/include/pmstep_store.h, the table's stepdir.* entries), with the
                       codes pmstep_console_stepdir_validate() refuses each with.
  codes.md             pmstep_status_t, pmstep_fault_t, pmstep_mode_t, pmstep_identification_t with
                       their texts (firmware/src/pmstep_text.c) and causes; the console's error reply
                       codes (with the host tool's texts, tools/pmstep_console.py ERRORS); the STM32G4
                       port's status codes (texts in hal/stm32g4/src/stm32g4_convert.c) and faults.
  console-protocol.md  the framing (the comment at the top of firmware/console/include/pmstep_console.h),
                       one row per request of requests[] (firmware/console/src/pmstep_console_request.c)
                       joined with the header's "Requests (DATA):" list, and the error reply codes.
  scenario-keys.md     every key of the SIL's scenario (scenario_keys[] of sil/src/scenario_keys.c) by
                       section, with the value names of the enumerated keys (sil/src/scenario_keys.h).

Tables in hand-written pages (--docs, default docs/ of this tree), each between its two markers
(PAGE_TABLES), written again in place:
  getting-started/nucleo-g431rb.md, stm32g4-stepdir-pins: the STEP/DIR input's pins of the STM32G4
                       port's default drive: the STEP/DIR rows of pmstep_stm32g4_pin_map() and the pins
                       pmstep_stm32g4_default_config() gives them (hal/stm32g4/src/stm32g4_board.c).

--sil PATH: a pmstep-sil binary. Its --print-scenario output must list the same keys, in the same
order and with the same help, as the parsed table (else the binary is stale or the parser wrong),
and the scenario-keys page gains a column with the built-in paper scenario's values.

The C tables are read with regular expressions: they have a fixed one-entry-per-line shape, and
any line of a table that does not have it raises GenError naming the file and line, so a change of
shape fails the documentation build instead of writing a wrong page. So does an inconsistency
between the tables: a code without a text or a text without a code, a console entry naming no
field or of another type, a sign rule on a field that is not a float, a field whose name has no
known unit suffix. Exit status: 0 written, 1 GenError (message on stderr). Notes (a code or field
without a doc comment, a float setting outside sign_rules[]) go to stderr and do not fail.
"""

from __future__ import annotations

import argparse
import ast
import re
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

TYPES_H = "firmware/include/pmstep/pmstep_types.h"
CONFIG_C = "firmware/src/pmstep_config.c"
TEXT_C = "firmware/src/pmstep_text.c"
CONSOLE_H = "firmware/console/include/pmstep_console.h"
CONSOLE_CONFIG_C = "firmware/console/src/pmstep_console_config.c"
CONSOLE_REQUEST_C = "firmware/console/src/pmstep_console_request.c"
CONSOLE_PY = "tools/pmstep_console.py"
STORE_H = "firmware/console/include/pmstep_store.h"
CALIBRATE_H = "firmware/design/include/pmstep/pmstep_calibrate.h"
STM32G4_H = "hal/stm32g4/include/pmstep_hal_stm32g4.h"
STM32G4_TEXT_C = "hal/stm32g4/src/stm32g4_convert.c"
STM32G4_BOARD_C = "hal/stm32g4/src/stm32g4_board.c"
SCENARIO_KEYS_C = "sil/src/scenario_keys.c"
SCENARIO_KEYS_H = "sil/src/scenario_keys.h"
# Every C source read above, line by line: its layout is this generator's input (--parsed-sources).
PARSED_C_SOURCES = (
    TYPES_H,
    CONFIG_C,
    TEXT_C,
    CONSOLE_H,
    CONSOLE_CONFIG_C,
    CONSOLE_REQUEST_C,
    STORE_H,
    CALIBRATE_H,
    STM32G4_H,
    STM32G4_TEXT_C,
    STM32G4_BOARD_C,
    SCENARIO_KEYS_C,
    SCENARIO_KEYS_H,
)

# The unit a field name's suffix gives; the longest suffix that ends the name wins (_Nm_A before _A).
UNIT_SUFFIXES = {
    "_A": "A",
    "_V": "V",
    "_Ohm": "Ohm",
    "_H": "H",
    "_s": "s",
    "_rad": "rad",
    "_rad_s": "rad/s",
    "_rad_s2": "rad/s^2",
    "_per_s": "1/s",
    "_per_s2": "1/s^2",
    "_Nm": "Nm",
    "_Nm_A": "Nm/A",
    "_kgm2": "kg m^2",
    "_Nms_rad": "Nm s/rad",
    "_Hz": "Hz",
    "_periods": "control periods",
    "_full_steps": "full steps",
}
# Numeric fields whose name carries no unit suffix (a plain number, or a coefficient whose unit its
# meaning states). Any other numeric field without a known suffix raises: a new unit is added to
# UNIT_SUFFIXES, not dropped.
UNSUFFIXED_FIELDS = {
    "motor.pole_pairs",
    "gains.adapt_gamma",
    "gains.adapt_lambda",
    "gains.adapt_r",
    "gains.angle_smoothing",
    "gains.transient_observer_boost",
    "commissioning.voltage_bias_level_fraction",
    "field_weakening.modulation",
    "detection.angle_magnitude_bound",
    "detection.max_realignments",
    "stepdir.microsteps",
    "stepdir.diag_mode",
}

# How the causes of the status codes (their doc comments) name a setting besides its own name
# (qualified, or bare where no other group has that name): the symbols of the paper and a few
# phrases. The longest phrase is matched first ("measured R" is the commissioning option, not R).
# Each phrase must occur in the cause of some status code init returns, else GenError: a stale
# phrase is removed, not kept.
FIELD_PHRASES = {
    "motor.resistance_Ohm": ["R"],
    "motor.inductance_H": ["L"],
    "motor.inertia_kgm2": ["J"],
    "motor.friction_Nms_rad": ["F"],
    "motor.torque_constant_Nm_A": ["k_M"],
    "motor.pole_pairs": ["p"],
    "timing.period_s": ["T_s", "one period"],
    "timing.computational_delay_periods": ["computational delay"],
    "alignment.s_align_time_s": ["t_s"],
    "alignment.c_align_time_s": ["t_c"],
    "alignment.s_align_voltage_V": ["u_cs"],
    "alignment.c_align_voltage_V": ["u_cc"],
    "gains.speed_gain_per_s": ["k_w"],
    "gains.observer_gain_per_s": ["K_e"],
    "gains.current_gain_per_s": ["K_i"],
    "gains.adapt_gamma": ["gamma"],
    "gains.adapt_lambda": ["lambda"],
    "gains.adapt_r": ["r"],
    "gains.sat_kappa_rad_s": ["kappa"],
    "gains.reference_bandwidth_rad_s": ["varpi_0"],
    "gains.transient_observer_boost": ["k"],
    "limits.min_bus_voltage_V": ["minimum bus voltage"],
    "commissioning.alignment_offset_calibration": ["offsets from the alignments"],
    "commissioning.steady_state_window_s": ["steady-state window"],
    "commissioning.inductance_window_s": ["current-rise window"],
    "commissioning.use_measured_resistance": ["measured R"],
    "commissioning.use_measured_inductance": ["measured L"],
    "commissioning.use_measured_torque_constant": ["measured k_M"],
    "commissioning.voltage_bias_level_fraction": ["voltage bias", "level drops"],
    "commissioning.identification_time_s": ["identification window"],
    "commissioning.use_identified_mechanics": ["identified J and F"],
    "commissioning.measure_only": ["measure_only"],
    "inverter.dead_time_s": ["t_d"],
    "standstill.hold_current_A": ["hold current", "standstill hold"],
    "standstill.vector_speed_rad_s": ["low-speed drive"],
}
# Status codes that concern every setting (stated once at the top, not on each row).
GENERAL_CODES = ("PMSTEP_ERR_NONFINITE_PARAMETER", "PMSTEP_ERR_DERIVED_NONFINITE")

SIGNS = {"SIGN_POSITIVE": "> 0", "SIGN_NON_NEGATIVE": ">= 0", "SIGN_ANY": None}

# The console's entry types and the C types they read.
CONSOLE_TYPES = {"F32": "float", "U32": "uint32_t", "I32": "int32_t", "BOOL": "bool"}

# The scenario's key types (key_type_t of sil/src/scenario_keys.h); the enumerated ones are those
# with a name array (KEY_LOAD_KIND: load_kind_names) and are described by their values.
KEY_TYPES = {
    "KEY_DOUBLE": "number",
    "KEY_FLOAT": "float32",
    "KEY_INT": "integer",
    "KEY_UINT": "unsigned integer",
    "KEY_BOOL": "true / false (or 1 / 0)",
    "KEY_ANGLE_DEG": "angle (degrees; stored in rad)",
    "KEY_ADC_BITS": "bits: 0 (ideal), or 8 to 16",
    "KEY_SPEED_POINTS": "t:value pairs, comma-separated",
    "KEY_LOAD_POINTS": "t:value pairs, comma-separated",
    "KEY_MOVES": "t:value pairs, comma-separated",
}
# Key types whose value the reader checks against the row's range (scenario.c: the number path).
RANGED_KEY_TYPES = {"KEY_DOUBLE", "KEY_FLOAT", "KEY_INT", "KEY_UINT", "KEY_ANGLE_DEG", "KEY_ADC_BITS"}


class GenError(Exception):
    """A source the generator does not understand, or an inconsistency between the code's tables."""


def rel(path: Path) -> str:
    try:
        return str(path.relative_to(ROOT))
    except ValueError:
        return str(path)


def note(message: str) -> None:
    print(f"gen_reference: note: {message}", file=sys.stderr)


class Source:
    """A source file's lines, with errors that name the file and line (1-based)."""

    def __init__(self, root: Path, relpath: str):
        self.path = root / relpath
        self.name = relpath
        try:
            self.lines = self.path.read_text(encoding="utf-8").split("\n")
        except OSError as e:
            raise GenError(f"{relpath}: cannot read: {e}") from e

    def error(self, index: int, message: str) -> GenError:
        return GenError(f"{self.name}:{index + 1}: {message}")

    def find_one(self, pattern: str, start: int = 0, end: int | None = None) -> tuple[int, re.Match]:
        """The one line in [start, end) matching @p pattern (re.match), else GenError."""
        regex = re.compile(pattern)
        hits = [
            (i, m) for i in range(start, len(self.lines) if end is None else end) if (m := regex.match(self.lines[i]))
        ]
        if len(hits) != 1:
            where = f"{self.name}:{hits[1][0] + 1}: " if len(hits) > 1 else f"{self.name}: "
            raise GenError(f"{where}expected one line matching {pattern!r}, found {len(hits)}")
        return hits[0]

    def table_rows(self, opening: str, table: str) -> tuple[int, list[tuple[int, str]]]:
        """An initialiser's rows: the line matching @p opening, then (index, line) of each line up to
        its closing "};" that is neither blank nor a plain comment; GenError if it is not closed."""
        start, _ = self.find_one(opening)
        rows = []
        for i in range(start + 1, len(self.lines)):
            line = self.lines[i]
            if line.strip() == "};":
                return start, rows
            if line.strip() and not PLAIN_COMMENT.match(line):
                rows.append((i, line))
        raise self.error(start, f"{table} not closed")


# ---------------------------------------------------------------------------------------------------
# C pieces
# ---------------------------------------------------------------------------------------------------


def clean(text: str) -> str:
    """Comment text on one line: whitespace collapsed."""
    return " ".join(text.split())


def c_string(src: Source, index: int, literal: str) -> str:
    """The value of a C string literal's body (between the quotes)."""
    out = []
    i = 0
    while i < len(literal):
        ch = literal[i]
        if ch == "\\":
            if i + 1 >= len(literal) or literal[i + 1] not in "\\\"'n":
                raise src.error(index, f"unsupported escape in string literal {literal!r}")
            out.append({"n": "\n"}.get(literal[i + 1], literal[i + 1]))
            i += 2
        elif ch == '"':
            raise src.error(index, f"unescaped quote in string literal {literal!r}")
        else:
            out.append(ch)
            i += 1
    return "".join(out)


STRING = r'"((?:[^"\\]|\\.)*)"'


def doc_comment_above(src: Source, index: int) -> str:
    """The /** ... */ block that ends on the line above @p index, or ''."""
    j = index - 1
    if j < 0 or not src.lines[j].rstrip().endswith("*/"):
        return ""
    end = j
    while j >= 0 and "/**" not in src.lines[j]:
        if "/*" in src.lines[j] and j != end:
            return ""
        j -= 1
    if j < 0:
        return ""
    text = " ".join(src.lines[j : end + 1])
    text = text[text.index("/**") + 3 : text.rindex("*/")]
    return clean(re.sub(r"(^|\s)\*(?=\s)", " ", text))


def typedef_body(src: Source, kind: str, name: str) -> tuple[int, int]:
    """Indices (first line of the body, line of the closing brace) of `typedef kind { ... } name;`."""
    close, _ = src.find_one(rf"^\}} {re.escape(name)};\s*$")
    for j in range(close - 1, -1, -1):
        if re.match(rf"^typedef {kind}(?: \w+)? \{{\s*$", src.lines[j]):
            return j + 1, close
        if src.lines[j].startswith("}") or src.lines[j].startswith("typedef"):
            break
    raise src.error(close, f"no 'typedef {kind} {{' opens {name}")


@dataclass
class EnumValue:
    name: str
    value: int
    doc: str
    group: str
    line: int


ENUM_ITEM = re.compile(r"^\s*(\w+)(?:\s*=\s*(-?(?:0[xX][0-9A-Fa-f]+|\d+)))?\s*(,?)\s*(?:/\*\*<(.*))?$")
PLAIN_COMMENT = re.compile(r"^\s*/\*(?![*])(.*)\*/\s*$")


def parse_enum(src: Source, name: str) -> list[EnumValue]:
    """The values of `typedef enum { ... } name;`, one per line, each with its /**< doc comment
    (continued on the lines below until */) and the last plain /* group */ comment above it."""
    first, close = typedef_body(src, "enum", name)
    values: list[EnumValue] = []
    group = ""
    next_value = 0
    comment_open: EnumValue | None = None
    last_comma = True
    for i in range(first, close):
        line = src.lines[i]
        if comment_open is not None:
            text, closed = (line.split("*/", 1)[0], True) if "*/" in line else (line, False)
            comment_open.doc = clean(comment_open.doc + " " + text)
            if closed:
                if line.split("*/", 1)[1].strip():
                    raise src.error(i, "text after the end of a doc comment")
                comment_open = None
            continue
        if not line.strip():
            continue
        if m := PLAIN_COMMENT.match(line):
            group = clean(m.group(1))
            continue
        m = ENUM_ITEM.match(line)
        if not m:
            raise src.error(i, f"enum {name}: line not understood: {line.strip()!r}")
        if not last_comma:
            raise src.error(i, f"enum {name}: the value above has no comma")
        value = int(m.group(2), 0) if m.group(2) is not None else next_value
        item = EnumValue(m.group(1), value, "", group, i + 1)
        if m.group(4) is not None:
            doc = m.group(4)
            if "*/" in doc:
                body, rest = doc.split("*/", 1)
                if rest.strip():
                    raise src.error(i, "text after the end of a doc comment")
                item.doc = clean(body)
            else:
                item.doc = clean(doc)
                comment_open = item
        values.append(item)
        next_value = value + 1
        last_comma = m.group(3) == ","
    if comment_open is not None:
        raise src.error(close, f"enum {name}: unterminated doc comment")
    if not values:
        raise src.error(close, f"enum {name} is empty")
    names = [v.name for v in values]
    if len(set(names)) != len(names):
        raise src.error(close, f"enum {name}: a name twice")
    return values


@dataclass
class Member:
    ctype: str
    name: str
    doc: str
    line: int


STRUCT_ITEM = re.compile(r"^\s*(?:const\s+)?(\w+)\s+(\w+)(?:\[\w+\])?;\s*(?:/\*\*<(.*))?$")


def parse_struct(src: Source, name: str) -> tuple[list[Member], str]:
    """The members of `typedef struct { ... } name;`, one per line with its /**< doc comment
    (continued on the lines below), and the struct's own doc comment."""
    first, close = typedef_body(src, "struct", name)
    members: list[Member] = []
    comment_open: Member | None = None
    for i in range(first, close):
        line = src.lines[i]
        if comment_open is not None:
            text, closed = (line.split("*/", 1)[0], True) if "*/" in line else (line, False)
            comment_open.doc = clean(comment_open.doc + " " + text)
            if closed:
                if line.split("*/", 1)[1].strip():
                    raise src.error(i, "text after the end of a doc comment")
                comment_open = None
            continue
        if not line.strip() or PLAIN_COMMENT.match(line):
            continue
        m = STRUCT_ITEM.match(line)
        if not m:
            raise src.error(i, f"struct {name}: line not understood: {line.strip()!r}")
        member = Member(m.group(1), m.group(2), "", i + 1)
        if m.group(3) is not None:
            doc = m.group(3)
            if "*/" in doc:
                body, rest = doc.split("*/", 1)
                if rest.strip():
                    raise src.error(i, "text after the end of a doc comment")
                member.doc = clean(body)
            else:
                member.doc = clean(doc)
                comment_open = member
        members.append(member)
    if comment_open is not None:
        raise src.error(close, f"struct {name}: unterminated doc comment")
    return members, doc_comment_above(src, first - 1)


def parse_text_function(src: Source, function: str) -> tuple[str, dict[str, str], str]:
    """`const char *function(enum_t x) { switch (x) { case A: return "..."; ... } return "..."; }`:
    the enum type, the text of each case, and the text after the switch. A case's return may be on
    the line below it."""
    start, m = src.find_one(rf"^const char \*{re.escape(function)}\((\w+) \w+\)\s*$")
    enum_type = m.group(1)
    i = start + 1
    expect = [r"^\{\s*$", r"^\s+switch \(\w+\) \{\s*$"]
    for pattern in expect:
        if i >= len(src.lines) or not re.match(pattern, src.lines[i]):
            raise src.error(i, f"{function}: expected {pattern!r}")
        i += 1
    texts: dict[str, str] = {}
    while True:
        if i >= len(src.lines):
            raise src.error(i - 1, f"{function}: no end of the switch")
        line = src.lines[i]
        if re.match(r"^\s+\}\s*$", line):
            i += 1
            break
        if m := re.match(rf"^\s+case (\w+):\s*return {STRING};\s*$", line):
            case, literal = m.group(1), m.group(2)
            i += 1
        elif m := re.match(r"^\s+case (\w+):\s*$", line):
            case = m.group(1)
            nxt = src.lines[i + 1] if i + 1 < len(src.lines) else ""
            m2 = re.match(rf"^\s+return {STRING};\s*$", nxt)
            if not m2:
                raise src.error(i + 1, f"{function}: expected the return of case {case}")
            literal = m2.group(1)
            i += 2
        elif not line.strip():
            i += 1
            continue
        else:
            raise src.error(i, f"{function}: line not understood: {line.strip()!r}")
        if case in texts:
            raise src.error(i - 1, f"{function}: case {case} twice")
        texts[case] = c_string(src, i - 1, literal)
    m = re.match(rf"^\s+return {STRING};\s*$", src.lines[i]) if i < len(src.lines) else None
    if not m or not (i + 1 < len(src.lines) and src.lines[i + 1].strip() == "}"):
        raise src.error(i, f"{function}: expected the return after the switch, then '}}'")
    return enum_type, texts, c_string(src, i, m.group(1))


def join_texts(
    values: list[EnumValue], texts: dict[str, str], src: Source, function: str, enum_name: str
) -> dict[str, str]:
    """Every value has a text and every text a value, else GenError (a real inconsistency)."""
    names = {v.name for v in values}
    missing = [v.name for v in values if v.name not in texts]
    extra = [c for c in texts if c not in names]
    problems = []
    if missing:
        problems.append(f"no text in {function}() for {', '.join(missing)}")
    if extra:
        problems.append(f"{function}() has a text for {', '.join(extra)}, not a value of {enum_name}")
    empty = [c for c, t in texts.items() if not t.strip()]
    if empty:
        problems.append(f"{function}() returns an empty text for {', '.join(empty)}")
    if problems:
        raise GenError(f"{src.name}: " + "; ".join(problems))
    return texts


def defines(src: Source) -> dict[str, tuple[str, str]]:
    """Object-like #defines of the file: name -> (replacement, trailing comment)."""
    out = {}
    for line in src.lines:
        m = re.match(r"^#define (\w+)[ \t]+(.*?)\s*(?:/\*+<?(.*?)\*/)?\s*$", line)
        if m and "(" not in line.split()[1]:
            out[m.group(1)] = (m.group(2).strip(), clean(m.group(3) or ""))
    return out


def c_int(expr: str, macros: dict[str, tuple[str, str]], src: Source, index: int, depth: int = 0) -> int:
    """An integer constant expression of literals (u suffixes), macros, + - * / and parentheses."""
    if depth > 8:
        raise src.error(index, f"macro nesting too deep in {expr!r}")

    def word(m: re.Match) -> str:
        w = m.group(0)
        if re.fullmatch(r"(0[xX][0-9A-Fa-f]+|\d+)[uU]?", w):
            return str(int(w.rstrip("uU"), 0))
        if w in macros:
            return str(c_int(macros[w][0], macros, src, index, depth + 1))
        raise src.error(index, f"unknown name {w!r} in {expr!r}")

    text = re.sub(r"\b\w+\b", word, expr)
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as e:
        raise src.error(index, f"not an integer expression: {expr!r}") from e
    allowed = (
        ast.Expression,
        ast.BinOp,
        ast.UnaryOp,
        ast.Constant,
        ast.Add,
        ast.Sub,
        ast.Mult,
        ast.FloorDiv,
        ast.Div,
        ast.USub,
        ast.UAdd,
    )
    if not all(isinstance(node, allowed) for node in ast.walk(tree)):
        raise src.error(index, f"not an integer expression: {expr!r}")
    text = text.replace("/", "//")
    return int(eval(compile(ast.parse(text, mode="eval"), src.name, "eval"), {"__builtins__": {}}))


def numeric_constants(src: Source) -> dict[str, str]:
    """#define NAME <number> of a header: name -> the number as written, without its f/u suffix."""
    out = {}
    for name, (value, _) in defines(src).items():
        if m := re.fullmatch(r"([-+]?(?:\d+\.?\d*(?:[eE][-+]?\d+)?|\.\d+))[fFuU]?", value):
            number = m.group(1)
            if re.fullmatch(r"\d+\.0", number):
                number = number[:-2]
            out[name] = number
    return out


# ---------------------------------------------------------------------------------------------------
# Markdown
# ---------------------------------------------------------------------------------------------------

_ESCAPES = {
    "\\": "&#92;",
    "[": "&#91;",
    "]": "&#93;",
    "<": "&lt;",
    "$": "&#36;",
    "`": "\\`",
    "*": "\\*",
    "_": "\\_",
    "{": "\\{",
    "}": "\\}",
    "|": "\\|",
}


def esc(text: str) -> str:
    """Plain text for a Markdown paragraph or table cell (Python-Markdown, with tables, attr_list and
    arithmatex): nothing in it is markup, a table delimiter, an HTML tag or math."""
    return "".join(_ESCAPES.get(ch, ch) for ch in text)


def code(text: str) -> str:
    if "`" in text or "\n" in text or not text:
        raise GenError(f"cannot put {text!r} in a code span")
    return f"`{text}`"


def table(headers: list[str], rows: list[list[str]]) -> list[str]:
    out = ["| " + " | ".join(headers) + " |", "|" + "|".join("---" for _ in headers) + "|"]
    for row in rows:
        if len(row) != len(headers):
            raise GenError(f"table row of {len(row)} cells under {len(headers)} headers: {row!r}")
        cells = [c if c.strip() else "&nbsp;" for c in row]
        if any("\n" in c for c in cells):
            raise GenError(f"a table cell holds a line break: {row!r}")
        out.append("| " + " | ".join(cells) + " |")
    return out


def generated_banner(sources: list[str]) -> list[str]:
    files = ", ".join(code(s) for s in sources)
    return [
        "<!-- Generated by tools/gen_reference.py: do not edit; edit the sources it reads and run it again. -->",
        "",
        '!!! note "Generated page"',
        f"    Written by {code('tools/gen_reference.py')} from {files}. Do not edit it: change the "
        "code and its comments, and the documentation build writes the page again.",
        "",
    ]


def rich(text: str, constants: dict[str, str], names: set[str] | frozenset[str] = frozenset()) -> str:
    """Escaped text of a comment with the PMSTEP_* and pmstep_* names (files, functions) and the
    settings' names (@p names) in code spans, each numeric constant of pmstep_types.h (@p constants)
    followed by its value."""
    alternatives = [r"\bPMSTEP_[A-Z0-9_]+\b", r"\bpmstep_[\w.]*\w(?:\(\))?"]
    if names:
        alternatives.insert(
            0, r"(?<![\w.])(?:" + "|".join(re.escape(n) for n in sorted(names, key=len, reverse=True)) + r")(?!\w)"
        )
    parts = re.split("(" + "|".join(alternatives) + ")", text)
    out = []
    for k, part in enumerate(parts):
        if k % 2 == 1 and part in constants:
            out.append(f"{code(part)} (= {esc(constants[part])})")
        elif k % 2 == 1:
            out.append(code(part))
        else:
            out.append(esc(part))
    return "".join(out)


def anchor(name: str) -> str:
    return name.lower()


def fmt_number(v: float) -> str:
    if v == int(v) and abs(v) < 1e15:
        s = str(int(v))
        m = re.fullmatch(r"(-?\d*?[1-9]|-?0)(0{6,})", s)
        return f"{m.group(1)}e{len(m.group(2))}" if m and m.group(1) not in ("0", "-0") else s
    s = repr(v)
    return re.sub(r"e([-+])0*(\d)", lambda m: "e" + ("-" if m.group(1) == "-" else "") + m.group(2), s)


# ---------------------------------------------------------------------------------------------------
# The configuration
# ---------------------------------------------------------------------------------------------------


@dataclass
class ConfigField:
    path: str  # motor.resistance_Ohm
    group: str  # motor, or "" for the top level
    ctype: str
    doc: str
    line: int
    console_id: int | None = None
    console_type: str | None = None
    read_only: bool = False
    sign: str | None = None
    sign_code: str | None = None
    codes: list[str] = field(default_factory=list)  # every code of init that names it, enum order


@dataclass
class ConfigGroup:
    name: str  # the member of pmstep_config_t, "" for the top level
    struct: str
    doc: str
    fields: list[ConfigField]


def unit_of(path: str, ctype: str) -> str:
    """The unit of a setting from its name's suffix; '' for a bool or a listed unsuffixed number."""
    if ctype == "bool":
        return ""
    for suffix in sorted(UNIT_SUFFIXES, key=len, reverse=True):
        if path.endswith(suffix):
            return UNIT_SUFFIXES[suffix]
    if path in UNSUFFIXED_FIELDS:
        return ""
    raise GenError(
        f"{path}: no known unit suffix (UNIT_SUFFIXES in tools/gen_reference.py); add the "
        f"suffix there, or the field to UNSUFFIXED_FIELDS if it is a plain number"
    )


def parse_config_fields(types_h: Source) -> list[ConfigGroup]:
    members, _ = parse_struct(types_h, "pmstep_config_t")
    struct_names = set(re.findall(r"^\} (\w+);", "\n".join(types_h.lines), re.M))
    groups: list[ConfigGroup] = []
    top = ConfigGroup("", "pmstep_config_t", "", [])
    for m in members:
        if m.ctype in struct_names:
            sub, sub_doc = parse_struct(types_h, m.ctype)
            fields = []
            for s in sub:
                if s.ctype in struct_names:
                    raise GenError(f"{types_h.name}:{s.line}: nested struct {s.ctype} in {m.ctype} not supported")
                fields.append(ConfigField(f"{m.name}.{s.name}", m.name, s.ctype, s.doc, s.line))
            groups.append(ConfigGroup(m.name, m.ctype, sub_doc, fields))
        else:
            top.fields.append(ConfigField(m.name, "", m.ctype, m.doc, m.line))
    if top.fields:
        groups.append(top)
    for g in groups:
        for f in g.fields:
            if f.ctype not in CONSOLE_TYPES.values():
                raise GenError(f"{types_h.name}:{f.line}: {f.path}: type {f.ctype} not known to the generator")
    return groups


def parse_console_table(src: Source) -> list[tuple[str, str, bool, int]]:
    """table[] of pmstep_console_config.c: (field path, console type, read-only, line) by id. The STEP/DIR
    settings' entries (pmstep_stepdir_settings_t, PMSTEP_CONSOLE_CFG_STEPDIR) have the path stepdir.<field>."""
    macros = {}
    for i, line in enumerate(src.lines):
        m = re.match(
            r"^#define (\w+)\(field\) \{#field, PMSTEP_CONSOLE_CFG_(\w+), (0u|PMSTEP_CONSOLE_CFG_READ_ONLY), "
            r"\(uint16_t\)offsetof\(pmstep_config_t, field\)\}\s*$",
            line,
        )
        sd = re.match(
            r'^#define (\w+)\(field\) \{"stepdir\." #field, PMSTEP_CONSOLE_CFG_(\w+), '
            r"PMSTEP_CONSOLE_CFG_STEPDIR, \(uint16_t\)offsetof\(pmstep_stepdir_settings_t, field\)\}\s*$",
            line,
        )
        if m or sd:
            kind = (m or sd).group(2)
            if kind not in CONSOLE_TYPES:
                raise src.error(i, f"console entry type {kind} not known to the generator")
            macros[(m or sd).group(1)] = (kind, m is not None and m.group(3) != "0u", "stepdir." if sd else "")
        elif line.startswith("#define") and "(field)" in line:
            raise src.error(i, "entry macro not understood")
    start, lines = src.table_rows(r"^static const pmstep_console_config_entry_t table\[\] = \{\s*$", "table[]")
    rows = []
    for i, line in lines:
        m = re.match(r"^\s*(\w+)\(([\w.]+)\),\s*$", line)
        if not m or m.group(1) not in macros:
            raise src.error(i, f"table[] line not understood: {line.strip()!r}")
        ctype, read_only, prefix = macros[m.group(1)]
        rows.append((prefix + m.group(2), ctype, read_only, i + 1))
    if not rows:
        raise src.error(start, "table[] is empty")
    return rows


STEPDIR_STRUCT = "pmstep_stepdir_settings_t"
STEPDIR_VALIDATE = "pmstep_console_stepdir_validate"


def parse_stepdir_group(store_h: Source) -> ConfigGroup:
    """The STEP/DIR settings (pmstep_stepdir_settings_t of pmstep_store.h) as the group stepdir."""
    members, doc = parse_struct(store_h, STEPDIR_STRUCT)
    fields = []
    for m in members:
        if m.ctype not in CONSOLE_TYPES.values():
            raise GenError(f"{store_h.name}:{m.line}: stepdir.{m.name}: type {m.ctype} not known to the generator")
        fields.append(ConfigField(f"stepdir.{m.name}", "stepdir", m.ctype, m.doc, m.line))
    return ConfigGroup("stepdir", STEPDIR_STRUCT, doc, fields)


def parse_stepdir_rules(src: Source, group: ConfigGroup, status_names: set[str]) -> None:
    """The codes pmstep_console_stepdir_validate() (pmstep_console_config.c) refuses each STEP/DIR setting
    with: every `if (...) { return CODE; }` of its body, the settings its condition reads (sd->field);
    into the fields' codes, in the checks' order."""
    start, _ = src.find_one(rf"^pmstep_status_t {STEPDIR_VALIDATE}\(")
    end = next((i for i in range(start, len(src.lines)) if src.lines[i] == "}"), None)
    if end is None:
        raise src.error(start, f"{STEPDIR_VALIDATE}() not closed")
    body = "\n".join(src.lines[start:end])
    fields = {f.path.split(".", 1)[1]: f for f in group.fields}
    checked = 0
    for m in re.finditer(r"if \((.*?)\) \{\s*return (\w+);\s*\}", body, re.S):
        names = re.findall(r"\bsd->(\w+)", m.group(1))
        code_name = m.group(2)
        if code_name not in status_names:
            raise src.error(start, f"{STEPDIR_VALIDATE}() returns {code_name}, not a value of pmstep_status_t")
        for n in names:
            if n not in fields:
                raise src.error(start, f"{STEPDIR_VALIDATE}() reads sd->{n}, not a field of {STEPDIR_STRUCT}")
            if code_name not in fields[n].codes:
                fields[n].codes.append(code_name)
        checked += bool(names)
    if not checked:
        raise src.error(start, f"{STEPDIR_VALIDATE}(): no check of a setting understood")


def parse_sign_rules(src: Source) -> list[tuple[str, str, str, int]]:
    """sign_rules[] of pmstep_config.c: (field path, SIGN_*, status code, line)."""
    _, lines = src.table_rows(r"^\s*static const sign_rule_t sign_rules\[\] = \{\s*$", "sign_rules[]")
    rows = []
    for i, line in lines:
        m = re.match(r"^\s*SIGN_RULE\(([\w.]+), (SIGN_\w+), (PMSTEP_\w+)\),\s*(?:/\*.*\*/\s*)?$", line)
        if not m:
            raise src.error(i, f"sign_rules[] line not understood: {line.strip()!r}")
        if m.group(2) not in SIGNS:
            raise src.error(i, f"sign {m.group(2)} not known to the generator")
        rows.append((m.group(1), m.group(2), m.group(3), i + 1))
    return rows


def phrase_matches(text: str, phrases: dict[str, str]) -> list[tuple[str, str]]:
    """(phrase, field) for every phrase found in @p text as whole words, longest phrases first; a
    stretch of text matched by a longer phrase is not matched again by a shorter one."""
    taken: list[tuple[int, int]] = []
    found = []
    for phrase in sorted(phrases, key=len, reverse=True):
        for m in re.finditer(rf"(?<!\w){re.escape(phrase)}(?!\w)", text):
            if any(m.start() < e and s < m.end() for s, e in taken):
                continue
            taken.append((m.start(), m.end()))
            found.append((phrase, phrases[phrase]))
    return found


@dataclass
class Reference:
    """Everything the pages are written from."""

    root: Path
    groups: list[ConfigGroup]
    console_rows: list[tuple[str, str, bool, int]]
    status: list[EnumValue]
    faults: list[EnumValue]
    modes: list[EnumValue]
    identification: list[EnumValue]
    texts: dict[str, dict[str, str]]  # enum type -> name -> text
    init_codes: list[str]  # status codes pmstep_config.c returns, enum order
    code_fields: dict[str, list[str]]  # status code -> settings its cause names
    constants: dict[str, str]
    names: set[str]  # the settings' names as comments write them
    console_errors: list[EnumValue]
    console_error_texts: dict[int, str]
    console_types: list[EnumValue]
    console: "ConsoleProtocol"
    stm32_status: list[EnumValue] | None
    stm32_faults: list[EnumValue] | None
    scenario: "Scenario"
    notes: list[str]

    def fields(self) -> list[ConfigField]:
        return [f for g in self.groups for f in g.fields]


def link_config(
    ref_groups: list[ConfigGroup],
    console_rows,
    sign_rules,
    status: list[EnumValue],
    init_codes: list[str],
    notes: list[str],
    types_h: Source,
    console_c: Source,
    config_c: Source,
) -> dict[str, list[str]]:
    fields = {f.path: f for g in ref_groups for f in g.fields}
    # console ids
    seen = set()
    for cid, (path, ctype, read_only, line) in enumerate(console_rows):
        if path not in fields:
            struct = STEPDIR_STRUCT if path.startswith("stepdir.") else "pmstep_config_t"
            raise GenError(f"{console_c.name}:{line}: table[] names {path}, not a field of {struct}")
        if path in seen:
            raise GenError(f"{console_c.name}:{line}: table[] names {path} twice")
        seen.add(path)
        f = fields[path]
        if CONSOLE_TYPES[ctype] != f.ctype:
            raise GenError(f"{console_c.name}:{line}: {path} is {ctype} on the console but {f.ctype} in {types_h.name}")
        f.console_id, f.console_type, f.read_only = cid, ctype, read_only
    # signs
    status_names = {v.name for v in status}
    for path, sign, code_name, line in sign_rules:
        if path not in fields:
            raise GenError(f"{config_c.name}:{line}: sign_rules[] names {path}, not a field of pmstep_config_t")
        f = fields[path]
        if f.ctype != "float":
            raise GenError(f"{config_c.name}:{line}: sign_rules[] reads {path} as a float, but it is {f.ctype}")
        if f.sign is not None or f.sign_code is not None:
            raise GenError(f"{config_c.name}:{line}: sign_rules[] names {path} twice")
        if code_name not in status_names:
            raise GenError(f"{config_c.name}:{line}: {code_name} is not a value of pmstep_status_t")
        if SIGNS[sign] is None:
            if code_name != "PMSTEP_OK":
                raise GenError(f"{config_c.name}:{line}: SIGN_ANY with a code other than PMSTEP_OK")
            f.sign, f.sign_code = "any", None
        else:
            if code_name == "PMSTEP_OK":
                raise GenError(f"{config_c.name}:{line}: a sign rule that refuses with PMSTEP_OK")
            f.sign, f.sign_code = SIGNS[sign], code_name
    for f in fields.values():
        if f.group == "stepdir":  # checked by pmstep_console_stepdir_validate(), not by init
            continue
        if f.ctype == "float" and f.sign is None:
            notes.append(
                f"{f.path} is a float setting outside sign_rules[] ({config_c.name}): init does not "
                "check that it is finite"
            )
        if f.sign == "any":
            f.sign = None
        if not f.doc:
            notes.append(f"{types_h.name}:{f.line}: {f.path} has no doc comment")
    # codes named by their causes
    bare_count: dict[str, int] = {}
    for path in fields:
        bare = path.rsplit(".", 1)[-1]
        bare_count[bare] = bare_count.get(bare, 0) + 1
    phrases: dict[str, str] = {}
    for path in fields:
        phrases[path] = path
        bare = path.rsplit(".", 1)[-1]
        if bare_count[bare] == 1:
            phrases[bare] = path
    for path, extra in FIELD_PHRASES.items():
        if path not in fields:
            raise GenError(f"FIELD_PHRASES in tools/gen_reference.py names {path}, not a field of pmstep_config_t")
        for phrase in extra:
            if phrase in phrases and phrases[phrase] != path:
                raise GenError(f"FIELD_PHRASES: {phrase!r} names both {phrases[phrase]} and {path}")
            phrases[phrase] = path
    by_name = {v.name: v for v in status}
    considered = [c for c in init_codes if c not in GENERAL_CODES]
    code_fields: dict[str, list[str]] = {}
    used_phrases = set()
    for c in considered:
        named = []
        for phrase, path in phrase_matches(by_name[c].doc, phrases):
            used_phrases.add(phrase)
            if path not in named:
                named.append(path)
        code_fields[c] = named
    stale = [p for extra in FIELD_PHRASES.values() for p in extra if p not in used_phrases]
    if stale:
        raise GenError(
            "FIELD_PHRASES in tools/gen_reference.py: no cause of a status code init returns uses "
            + ", ".join(repr(p) for p in stale)
            + " any more: remove or update it"
        )
    for f in fields.values():
        if f.group == "stepdir":  # its codes are pmstep_console_stepdir_validate()'s (parse_stepdir_rules)
            for c in f.codes:
                code_fields.setdefault(c, []).append(f.path)
            continue
        codes = {c for c in considered if f.path in code_fields[c]}
        if f.sign_code:
            codes.add(f.sign_code)
            if f.path not in code_fields.setdefault(f.sign_code, []):
                code_fields[f.sign_code].append(f.path)
        f.codes = ([f.sign_code] if f.sign_code else []) + [
            v.name for v in status if v.name in codes and v.name != f.sign_code
        ]
    # settings in field order for each code
    order = {p: k for k, p in enumerate(fields)}
    return {c: sorted(ps, key=order.__getitem__) for c, ps in code_fields.items()}


# ---------------------------------------------------------------------------------------------------
# The console protocol
# ---------------------------------------------------------------------------------------------------


@dataclass
class Request:
    code: int
    name: str  # HELLO (pmstep_console_type_t without PMSTEP_CONSOLE_)
    needs: str  # NEEDS_*
    needs_text: str  # the macro's comment
    min_length: int
    max_length: int
    data: str  # from the header's list
    reply: str


@dataclass
class ConsoleProtocol:
    prose_before: list[tuple[str, str]]  # ("text" | "pre", content) paragraphs before the request list
    prose_after: list[tuple[str, str]]
    requests: list[Request]
    other_types: list[EnumValue]  # pmstep_console_type_t values that are not requests
    constants: list[tuple[str, str, str]]  # PMSTEP_CONSOLE_* macros: name, value, comment
    shared_replies: list[tuple[Request, str]]  # a request whose reply TYPE is another frame's TYPE too


def header_comment(src: Source) -> tuple[int, int]:
    """Indices of the lines of the file's leading /** ... */ comment (first after /**, the */ line)."""
    if not src.lines or src.lines[0].strip() != "/**":
        raise src.error(0, "expected the file to open with a /** comment")
    for i, line in enumerate(src.lines):
        if line.strip() == "*/":
            return 1, i
    raise src.error(0, "the leading comment is not closed")


def comment_body(src: Source, i: int) -> str:
    line = src.lines[i]
    if line.rstrip() == " *":
        return ""
    if not line.startswith(" * "):
        raise src.error(i, f"comment line not understood: {line!r}")
    return line[3:].rstrip()


def paragraphs(src: Source, first: int, end: int) -> list[tuple[str, str]]:
    """Comment lines [first, end) as paragraphs: ('pre', text) where every line is indented by 4 or
    more (a layout), else ('text', the lines joined)."""
    out: list[tuple[str, str]] = []
    block: list[str] = []

    def flush() -> None:
        if block:
            if all(b.startswith("    ") for b in block):
                width = min(len(b) - len(b.lstrip()) for b in block)
                out.append(("pre", "\n".join(b[width:] for b in block)))
            else:
                out.append(("text", clean(" ".join(block))))
            block.clear()

    for i in range(first, end):
        body = comment_body(src, i)
        if body.strip():
            block.append(body)
        else:
            flush()
    flush()
    return out


REQUEST_START = re.compile(r"^  (0x[0-9A-F]{2}) ([A-Z_]+)(.*)$")


def parse_header_requests(src: Source, types: list[EnumValue]) -> tuple[dict[str, tuple[str, str]], int, int, int]:
    """The header's "Requests (DATA):" list: request name -> (DATA, reply), and the list's lines."""
    first, end = header_comment(src)
    start, _ = src.find_one(r"^ \* Requests \(DATA\):\s*$", first, end)
    codes = {v.name.removeprefix("PMSTEP_CONSOLE_"): v.value for v in types}
    entries: list[list[str]] = []
    i = start + 1
    while i < end and comment_body(src, i).strip():
        body = comment_body(src, i)
        if REQUEST_START.match(body):
            entries.append([body])
        elif body.startswith("    ") and entries:
            entries[-1].append(body.strip())
        else:
            raise src.error(i, f"request list line not understood: {body!r}")
        i += 1
    list_end = i
    out: dict[str, tuple[str, str]] = {}
    for entry in entries:
        text = clean(" ".join(entry))
        if text.count("->") < 1:
            raise src.error(start, f"request list entry without '->': {text!r}")
        left, reply = (s.strip() for s in text.split("->", 1))
        names = []
        rest = left
        while m := re.match(r"^(0x[0-9A-F]{2}) ([A-Z_]+)(,\s*)?", rest):
            names.append((int(m.group(1), 16), m.group(2)))
            rest = rest[m.end() :]
            if not m.group(3):
                break
        data = rest.strip()
        if not names or not data:
            raise src.error(start, f"request list entry not understood: {text!r}")
        for code_value, name in names:
            if codes.get(name) != code_value:
                raise src.error(
                    start, f"request list: 0x{code_value:02X} {name} is not a value of pmstep_console_type_t"
                )
            if name in out:
                raise src.error(start, f"request list: {name} twice")
            out[name] = (data, reply)
    return out, start, list_end, end


def parse_console(console_h: Source, request_c: Source, types: list[EnumValue]) -> ConsoleProtocol:
    listed, list_start, list_end, comment_end = parse_header_requests(console_h, types)
    first, _ = console_h.find_one(r"^ \* Frame \(both directions\):\s*$", 0, comment_end)
    before = paragraphs(console_h, first, list_start)
    after = paragraphs(console_h, list_end, comment_end)
    macros = {**defines(console_h), **defines(request_c)}
    start, lines = request_c.table_rows(r"^static const request_row_t requests\[\] = \{\s*$", "requests[]")
    by_name = {v.name: v for v in types}
    requests = []
    for i, line in lines:
        m = re.match(r"^\s*\{(PMSTEP_CONSOLE_\w+), (NEEDS_\w+), (\w+), (\w+), (\w+)\},\s*$", line)
        if not m:
            raise request_c.error(i, f"requests[] line not understood: {line.strip()!r}")
        if m.group(1) not in by_name:
            raise request_c.error(i, f"{m.group(1)} is not a value of pmstep_console_type_t")
        if m.group(2) not in macros:
            raise request_c.error(i, f"{m.group(2)} is not defined")
        name = m.group(1).removeprefix("PMSTEP_CONSOLE_")
        if name not in listed:
            raise request_c.error(
                i, f'{name} is in requests[] but not in the "Requests (DATA):" list of {console_h.name}'
            )
        lo, hi = c_int(m.group(3), macros, request_c, i), c_int(m.group(4), macros, request_c, i)
        if lo > hi:
            raise request_c.error(i, f"{name}: DATA length {lo} > {hi}")
        data, reply = listed[name]
        requests.append(
            Request(by_name[m.group(1)].value, name, m.group(2), macros[m.group(2)][1], lo, hi, data, reply)
        )
    in_table = {r.name for r in requests}
    if len(in_table) != len(requests):
        raise request_c.error(start, "requests[] has a type twice")
    unlisted = [n for n in listed if n not in in_table]
    if unlisted:
        raise GenError(
            f'{console_h.name}: the "Requests (DATA):" list has {", ".join(unlisted)}, which '
            f"requests[] of {request_c.name} does not serve"
        )
    others = [v for v in types if v.name.removeprefix("PMSTEP_CONSOLE_") not in in_table]
    constants = [
        (n, v, c)
        for n, (v, c) in defines(console_h).items()
        if n.startswith("PMSTEP_CONSOLE_")
        and not n.startswith(("PMSTEP_CONSOLE_CFG_", "PMSTEP_CONSOLE_POSITION_"))
        and not n.endswith("_H")
    ]
    shared = []
    for r in requests:
        for v in types:
            if v.value == (r.code | 0x80) and v.name.removeprefix("PMSTEP_CONSOLE_") != r.name:
                shared.append((r, v.name))
    return ConsoleProtocol(before, after, requests, others, constants, shared)


def host_error_texts(root: Path, errors: list[EnumValue]) -> dict[int, str]:
    """ERRORS of tools/pmstep_console.py (the host tool's text of each error reply code)."""
    path = root / CONSOLE_PY
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=CONSOLE_PY)
    found = None
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "ERRORS" for t in node.targets):
            if found is not None:
                raise GenError(f"{CONSOLE_PY}:{node.lineno}: ERRORS assigned twice")
            try:
                found = (ast.literal_eval(node.value), node.lineno)
            except ValueError as e:
                raise GenError(f"{CONSOLE_PY}:{node.lineno}: ERRORS is not a literal") from e
    if found is None:
        raise GenError(f"{CONSOLE_PY}: no ERRORS = {{...}}")
    texts, line = found
    codes = {v.value for v in errors}
    if set(texts) != codes:
        raise GenError(
            f"{CONSOLE_PY}:{line}: ERRORS has the codes {sorted(texts)}, pmstep_console_error_t {sorted(codes)}"
        )
    return texts


# ---------------------------------------------------------------------------------------------------
# The scenario keys
# ---------------------------------------------------------------------------------------------------


@dataclass
class ScenarioKey:
    name: str
    type: str
    min: float
    min_exclusive: bool
    max: float
    max_exclusive: bool
    help: str
    line: int
    default: str | None = None


@dataclass
class Scenario:
    keys: list[ScenarioKey]
    enums: dict[str, list[str]]  # key type -> value names (in the C enum's order)
    enum_arrays: dict[str, str]  # key type -> the name array
    big: str  # the table's "no bound" magnitude, as written
    defaults_from: str | None = None


def parse_scenario(keys_c: Source, keys_h: Source) -> Scenario:
    text_h = "\n".join(keys_h.lines)
    m = re.search(r"typedef enum \{([^}]*)\} key_type_t;", text_h)
    if not m:
        raise GenError(f"{keys_h.name}: no 'typedef enum {{ ... }} key_type_t;'")
    key_types = [t.strip() for t in m.group(1).split(",") if t.strip()]
    if not all(re.fullmatch(r"KEY_[A-Z_]+", t) for t in key_types):
        raise GenError(f"{keys_h.name}: key_type_t not understood: {key_types}")
    arrays: dict[str, list[str]] = {}
    for i, line in enumerate(keys_h.lines):
        if "_names[]" in line:
            a = re.match(r"^static const char \*const (\w+)_names\[\] = \{(.*)\};\s*(?:/\*.*\*/\s*)?$", line)
            if not a:
                raise keys_h.error(i, f"name array not understood: {line.strip()!r}")
            items = [s.strip() for s in a.group(2).split(",")]
            values = []
            for item in items:
                s = re.fullmatch(STRING, item)
                if not s:
                    raise keys_h.error(i, f"name array item not understood: {item!r}")
                values.append(c_string(keys_h, i, s.group(1)))
            arrays[a.group(1)] = values
    enums, enum_arrays = {}, {}
    for t in key_types:
        array = t.removeprefix("KEY_").lower()
        if array in arrays:
            enums[t] = arrays[array]
            enum_arrays[t] = f"{array}_names"
        elif t not in KEY_TYPES:
            raise GenError(
                f"{keys_h.name}: key type {t} has no name array and no text in KEY_TYPES of tools/gen_reference.py"
            )
    for array in arrays:
        if "KEY_" + array.upper() not in key_types:
            raise GenError(f"{keys_h.name}: {array}_names names the values of no key type (KEY_{array.upper()})")
    macros = {}
    for line in keys_c.lines:
        if d := re.match(r"^#define (\w+) ([-+]?[\d.]+(?:[eE][-+]?\d+)?)\s*$", line):
            macros[d.group(1)] = d.group(2)
    if "BIG" not in macros:
        raise GenError(f"{keys_c.name}: no '#define BIG <number>'")
    number = r"(-?(?:BIG|[\d.]+(?:[eE][-+]?\d+)?))"
    row = re.compile(
        rf"^\s*\{{{STRING}, (KEY_[A-Z_]+), (?:OFF\([\w.]+\)|0), {number}, ([01]), {number}, ([01]), "
        rf"{STRING}\}},\s*$"
    )
    start, lines = keys_c.table_rows(r"^const key_t_ scenario_keys\[\] = \{\s*$", "scenario_keys[]")
    keys = []
    for i, line in lines:
        r = row.match(line)
        if not r:
            raise keys_c.error(i, f"scenario_keys[] line not understood: {line.strip()[:80]!r}")
        if r.group(2) not in key_types:
            raise keys_c.error(i, f"{r.group(2)} is not a value of key_type_t")

        def value(s: str) -> float:
            neg = s.startswith("-")
            v = float(macros["BIG"]) if s.lstrip("-") == "BIG" else float(s.lstrip("-"))
            return -v if neg else v

        name = c_string(keys_c, i, r.group(1))
        if not re.fullmatch(r"[a-z_0-9]+(\.[a-z_0-9]+)*\.[A-Za-z_0-9]+", name):
            raise keys_c.error(i, f"key {name!r} is not section.key")
        keys.append(
            ScenarioKey(
                name,
                r.group(2),
                value(r.group(3)),
                r.group(4) == "1",
                value(r.group(5)),
                r.group(6) == "1",
                c_string(keys_c, i, r.group(7)),
                i + 1,
            )
        )
    names = [k.name for k in keys]
    if len(set(names)) != len(names):
        raise keys_c.error(start, "scenario_keys[] has a key twice")
    if not keys:
        raise keys_c.error(start, "scenario_keys[] is empty")
    return Scenario(keys, enums, enum_arrays, macros["BIG"])


def sil_defaults(sil: Path, scenario: Scenario) -> None:
    """Cross-checks the table against `sil --print-scenario` and takes its values as defaults."""
    try:
        run = subprocess.run([str(sil), "--print-scenario"], capture_output=True, text=True, timeout=60)
    except OSError as e:
        raise GenError(f"--sil {sil}: cannot run: {e}") from e
    except subprocess.TimeoutExpired as e:
        raise GenError(f"--sil {sil}: --print-scenario did not finish in 60 s") from e
    if run.returncode != 0:
        raise GenError(f"--sil {sil}: --print-scenario exited {run.returncode}: {run.stderr.strip()}")
    printed: list[tuple[str, str, str]] = []  # key, help, value
    section = None
    help_text = None
    for n, line in enumerate(run.stdout.split("\n"), 1):
        if not line.strip():
            continue
        if m := re.fullmatch(r"\[([\w.]+)\]", line):
            section = m.group(1)
        elif line.startswith("; "):
            help_text = line[2:]
        elif line.startswith("    ") and printed:
            key, h, v = printed[-1]
            printed[-1] = (key, h, v + " " + line.strip())
        elif m := re.fullmatch(r"(\w+) = (.*)", line):
            if section == "scenario" and m.group(1) == "name":
                continue
            if section is None or help_text is None:
                raise GenError(f"--sil {sil} --print-scenario, line {n}: a key outside a section or without help")
            printed.append((f"{section}.{m.group(1)}", help_text, m.group(2)))
            help_text = None
        else:
            raise GenError(f"--sil {sil} --print-scenario, line {n} not understood: {line!r}")
    table_keys = [k.name for k in scenario.keys]
    printed_keys = [p[0] for p in printed]
    if printed_keys != table_keys:
        only_table = [k for k in table_keys if k not in printed_keys]
        only_sil = [k for k in printed_keys if k not in table_keys]
        raise GenError(
            f"--sil {sil}: its keys differ from {SCENARIO_KEYS_C} (a stale binary?): only in the table: "
            f"{only_table or 'none'}; only in the binary: {only_sil or 'none'}"
            + ("; same keys, another order" if not only_table and not only_sil else "")
        )
    for k, (_, h, v) in zip(scenario.keys, printed):
        if h != k.help:
            raise GenError(f"--sil {sil}: help of {k.name} differs from {SCENARIO_KEYS_C}:{k.line} (a stale binary?)")
        k.default = v
    scenario.defaults_from = str(sil)


# ---------------------------------------------------------------------------------------------------
# Reading everything
# ---------------------------------------------------------------------------------------------------


def load(root: Path = ROOT, sil: Path | None = None) -> Reference:
    notes: list[str] = []
    types_h = Source(root, TYPES_H)
    config_c = Source(root, CONFIG_C)
    text_c = Source(root, TEXT_C)
    console_h = Source(root, CONSOLE_H)
    console_c = Source(root, CONSOLE_CONFIG_C)
    request_c = Source(root, CONSOLE_REQUEST_C)

    status = parse_enum(types_h, "pmstep_status_t")
    faults = parse_enum(types_h, "pmstep_fault_t")
    modes = parse_enum(types_h, "pmstep_mode_t")
    identification = parse_enum(types_h, "pmstep_identification_t")
    enums = {
        "pmstep_status_t": status,
        "pmstep_fault_t": faults,
        "pmstep_mode_t": modes,
        "pmstep_identification_t": identification,
    }
    texts: dict[str, dict[str, str]] = {}
    for function, enum_name in (
        ("pmstep_status_str", "pmstep_status_t"),
        ("pmstep_fault_str", "pmstep_fault_t"),
        ("pmstep_mode_str", "pmstep_mode_t"),
        ("pmstep_identification_str", "pmstep_identification_t"),
    ):
        enum_type, found, _ = parse_text_function(text_c, function)
        if enum_type != enum_name:
            raise GenError(f"{text_c.name}: {function}() takes {enum_type}, expected {enum_name}")
        texts[enum_name] = join_texts(enums[enum_name], found, text_c, function, enum_name)
    for values in enums.values():
        if len({v.value for v in values}) != len(values):
            raise GenError(f"{types_h.name}: two names share a value in an enum")

    groups = parse_config_fields(types_h) + [parse_stepdir_group(Source(root, STORE_H))]
    for g in groups:
        for f in g.fields:
            unit_of(f.path, f.ctype)  # raises on an unknown suffix
    console_rows = parse_console_table(console_c)
    sign_rules = parse_sign_rules(config_c)
    names = {v.name for v in status}
    config_text = "\n".join(config_c.lines)
    returned = set(re.findall(r"\bPMSTEP_ERR_\w+\b", config_text))
    unknown = sorted(returned - names)
    if unknown:
        raise GenError(f"{config_c.name}: {', '.join(unknown)} not values of pmstep_status_t")
    init_codes = [v.name for v in status if v.name in returned]
    parse_stepdir_rules(console_c, groups[-1], names)
    code_fields = link_config(groups, console_rows, sign_rules, status, init_codes, notes, types_h, console_c, config_c)
    constants = numeric_constants(types_h)
    for values, what in (
        (status, "status code"),
        (faults, "fault code"),
        (modes, "mode"),
        (identification, "identification outcome"),
    ):
        for v in values:
            if not v.doc and v.value != 0:
                notes.append(f"{types_h.name}:{v.line}: {what} {v.name} has no doc comment (no cause on the page)")

    console_types = parse_enum(console_h, "pmstep_console_type_t")
    console_errors = parse_enum(console_h, "pmstep_console_error_t")
    for v in console_errors:
        if not v.doc:
            notes.append(f"{console_h.name}:{v.line}: console error {v.name} has no doc comment")
    console_error_texts = host_error_texts(root, console_errors)
    console = parse_console(console_h, request_c, console_types)
    for r, other in console.shared_replies:
        notes.append(f"{console_h.name}: the reply to {r.name} (TYPE 0x{r.code | 0x80:02X}) has the TYPE of {other}")

    stm32_status = stm32_faults = None
    if (root / STM32G4_H).exists():
        stm32_h = Source(root, STM32G4_H)
        stm32_c = Source(root, STM32G4_TEXT_C)
        stm32_status = parse_enum(stm32_h, "pmstep_stm32g4_status_t")
        stm32_faults = parse_enum(stm32_h, "pmstep_stm32g4_fault_t")
        enum_type, found, _ = parse_text_function(stm32_c, "pmstep_stm32g4_status_str")
        if enum_type != "pmstep_stm32g4_status_t":
            raise GenError(f"{stm32_c.name}: pmstep_stm32g4_status_str() takes {enum_type}")
        texts["pmstep_stm32g4_status_t"] = join_texts(
            stm32_status, found, stm32_c, "pmstep_stm32g4_status_str", "pmstep_stm32g4_status_t"
        )
        for v in stm32_status:
            if not v.doc and v.value != 0:
                notes.append(f"{stm32_h.name}:{v.line}: {v.name} has no doc comment")

    scenario = parse_scenario(Source(root, SCENARIO_KEYS_C), Source(root, SCENARIO_KEYS_H))
    if sil is not None:
        sil_defaults(sil, scenario)
    all_paths = [f.path for g in groups for f in g.fields]
    bare = [p.rsplit(".", 1)[-1] for p in all_paths]
    names = set(all_paths) | {b for b in bare if bare.count(b) == 1}
    return Reference(
        root,
        groups,
        console_rows,
        status,
        faults,
        modes,
        identification,
        texts,
        init_codes,
        code_fields,
        constants,
        names,
        console_errors,
        console_error_texts,
        console_types,
        console,
        stm32_status,
        stm32_faults,
        scenario,
        notes,
    )


# ---------------------------------------------------------------------------------------------------
# Pages
# ---------------------------------------------------------------------------------------------------


def code_link(name: str) -> str:
    return f"[{code(name)}](codes.md#{anchor(name)})"


def field_anchor(path: str) -> str:
    return "cfg-" + path.replace(".", "-").lower()


def range_cell(ref: Reference, f: ConfigField) -> str:
    by_name = {v.name: v for v in ref.status}
    lines = []
    if f.sign:
        lines.append(code(f.sign))
    for c in f.codes:
        lines.append(f"{code_link(c)}: {rich(by_name[c].doc, ref.constants, ref.names)}")
    if not lines:
        return "any" if f.ctype == "bool" else "not checked by init"
    return "<br>".join(lines)


def config_row(ref: Reference, f: ConfigField) -> list[str]:
    if f.console_id is None:
        cid, access = "-", "not exposed"
    else:
        cid, access = str(f.console_id), "read-only" if f.read_only else "read/write"
    unit = unit_of(f.path, f.ctype)
    return [
        cid,
        code(f.path) + f'<span id="{field_anchor(f.path)}"></span>',
        code(f.ctype),
        esc(unit) if unit else "-",
        access,
        rich(f.doc, ref.constants, ref.names) if f.doc else "-",
        range_cell(ref, f),
    ]


def page_configuration(ref: Reference) -> str:
    out = ["# Configuration", ""]
    out += generated_banner([TYPES_H, STORE_H, CONSOLE_CONFIG_C, CONFIG_C])
    core = [f for f in ref.fields() if f.group != "stepdir"]
    exposed = sum(1 for f in core if f.console_id is not None)
    out += [
        f"Every setting of {code('pmstep_config_t')}, grouped by its sub-structures, then the "
        f"[STEP/DIR settings](#stepdir) the console keeps and stores with them. "
        f"The console exposes {exposed} of the {len(core)} settings of {code('pmstep_config_t')}; "
        "**Id** is its position in the console's table (GET\\_CONFIG / SET\\_CONFIG by id or by name, "
        "the name being the setting's path), `-` where the console does not expose the setting. "
        "A read-only setting is fixed by the port (its hardware) and refused by SET\\_CONFIG. "
        "**Unit** comes from the name's suffix (`-`: the name carries none; the meaning may give it).",
        "",
        f"**Range** is what {code('pmstep_init()')} (its {code('pmstep_validate_config()')}) accepts: the sign "
        f"the table {code('sign_rules[]')} requires, then every status code that init returns whose cause names "
        "the setting, with that cause (init refuses the configuration with the first such code, in the order "
        f"of {code('pmstep_validate_config()')}). Besides, every float setting must be finite "
        f"({code_link('PMSTEP_ERR_NONFINITE_PARAMETER')}) and so must the coefficients derived from them "
        f"({code_link('PMSTEP_ERR_DERIVED_NONFINITE')}).",
        "",
    ]
    for g in ref.groups:
        title = g.name if g.name else "Top level"
        out += [f"## {title}", ""]
        struct = f"{code(g.struct)}" + (f": {esc(g.doc)}" if g.doc else "")
        if g.name == "stepdir":
            out += [
                f"Not part of {code('pmstep_config_t')}: the STEP/DIR settings, a {struct}",
                "",
                "The console reads and writes them by name (`stepdir.` and the field) as the settings "
                "above, with the motor stopped; a record holds them with the rest. **Range** is what "
                rf"{code(STEPDIR_VALIDATE + '()')} accepts (SET\_CONFIG's ACK and a record's check give "
                "its code); the core does not read them.",
                "",
            ]
        elif g.name:
            out += [f"{code(g.name)} is a {struct}", ""]
        else:
            out += [f"Members of {code('pmstep_config_t')} itself.", ""]
        rows = [config_row(ref, f) for f in g.fields]
        last = "Range" if g.name == "stepdir" else "Range (init)"
        out += table(["Id", "Setting", "Type", "Unit", "Console", "Meaning", last], rows)
        out.append("")
    return "\n".join(out)


def enum_table(
    values: list[EnumValue],
    texts: dict[str, str] | None,
    ref: Reference,
    text_header: str,
    extra: dict[str, str] | None = None,
    extra_header: str | None = None,
    group: bool = False,
) -> list[str]:
    headers = ["Code", "Name"] + ([text_header] if texts is not None else []) + ["Cause"]
    if group:
        headers.append("Group")
    if extra is not None:
        headers.append(extra_header or "")
    rows = []
    for v in values:
        name_cell = code(v.name) + f'<span id="{anchor(v.name)}"></span>'
        row = [str(v.value), name_cell]
        if texts is not None:
            row.append(esc(texts[v.name]))
        row.append(rich(v.doc, ref.constants, ref.names) if v.doc else "-")
        if group:
            row.append(esc(v.group.rstrip(".")) if v.group else "-")
        if extra is not None:
            row.append(extra.get(v.name, "-"))
        rows.append(row)
    return table(headers, rows)


def page_codes(ref: Reference) -> str:
    sources = [TYPES_H, TEXT_C, CONSOLE_H, CONSOLE_PY]
    if ref.stm32_status is not None:
        sources += [STM32G4_H, STM32G4_TEXT_C]
    out = ["# Status, fault and mode codes", ""]
    out += generated_banner(sources)
    out += [
        "**Text** is what the firmware's text functions return for the code (the console tool and the SIL "
        "print it); **Cause** is the code's doc comment.",
        "",
        f"## Status codes ({code('pmstep_status_t')})",
        "",
        f"Returned by every fallible call: 0 ok, negative a cause. Text: {code('pmstep_status_str()')}. "
        f"**Settings**: for the codes {code('pmstep_init()')} returns, the settings the cause names; for "
        f"the STEP/DIR codes, the STEP/DIR settings {code(STEPDIR_VALIDATE + '()')} refuses with them "
        "(see [Configuration](configuration.md)).",
        "",
    ]
    settings = {
        c: "<br>".join(f"[{code(p)}](configuration.md#{field_anchor(p)})" for p in ps)
        for c, ps in ref.code_fields.items()
        if ps
    }
    out += enum_table(ref.status, ref.texts["pmstep_status_t"], ref, "Text", settings, "Settings", group=True)
    out += [
        "",
        f"## Fault codes ({code('pmstep_fault_t')})",
        "",
        f"Latched by {code('pmstep_step()')} (the drive goes to FAULT, bridge off). "
        f"Text: {code('pmstep_fault_str()')}.",
        "",
    ]
    out += enum_table(ref.faults, ref.texts["pmstep_fault_t"], ref, "Text")
    out += ["", f"## Modes ({code('pmstep_mode_t')})", "", f"Text: {code('pmstep_mode_str()')}.", ""]
    out += enum_table(ref.modes, ref.texts["pmstep_mode_t"], ref, "Text")
    out += [
        "",
        f"## Identification outcomes ({code('pmstep_identification_t')})",
        "",
        f"The identification of J and F at the start of RUN. Text: {code('pmstep_identification_str()')}.",
        "",
    ]
    out += enum_table(ref.identification, ref.texts["pmstep_identification_t"], ref, "Text")
    out += ["", f"## Console error replies ({code('pmstep_console_error_t')})", ""]
    out += console_errors_section(ref)
    out += [
        "",
        f"## Stored configuration status codes ({code('pmstep_store_status_t')})",
        "",
        f"What a load, save, erase or a record written on the console came to ({code(STORE_H)}); an ACK of "
        f"{code('CONFIG_APPLY')}, {code('CONFIG_SAVE')} or {code('CONFIG_ERASE')} carries one, and "
        f"{code('CONFIG_STATUS')} the boot's.",
        "",
    ]
    out += enum_table(parse_enum(Source(ref.root, STORE_H), "pmstep_store_status_t"), None, ref, "")
    out += [
        "",
        f"## Self-commissioning status codes ({code('pmstep_calibrate_status_t')})",
        "",
        f"Why a calibration ({code(CALIBRATE_H)}) failed: {code('CALIBRATE_STATUS')}'s status; a design the designer "
        "or the core refused gives its status code above instead.",
        "",
    ]
    out += enum_table(parse_enum(Source(ref.root, CALIBRATE_H), "pmstep_calibrate_status_t"), None, ref, "")
    if ref.stm32_status is not None:
        out += [
            "",
            f"## STM32G4 port status codes ({code('pmstep_stm32g4_status_t')})",
            "",
            f"Returned by the port's set-up calls. Text: {code('pmstep_stm32g4_status_str()')}.",
            "",
        ]
        out += enum_table(ref.stm32_status, ref.texts["pmstep_stm32g4_status_t"], ref, "Text")
        out += [
            "",
            f"## STM32G4 port faults ({code('pmstep_stm32g4_fault_t')})",
            "",
            "Why the port holds the bridge off, independently of the core (the console's "
            f"{code('port_fault')}). The port has no text function for these.",
            "",
        ]
        out += enum_table(ref.stm32_faults, None, ref, "")
    out.append("")
    return "\n".join(out)


def console_errors_section(ref: Reference, anchors: bool = True) -> list[str]:
    out = [
        f"An error reply has TYPE 0xFF and DATA = the request's TYPE, then one of these codes. "
        f"Text: the host tool's ({code(CONSOLE_PY)}, {code('ERRORS')}).",
        "",
    ]
    rows = []
    for v in ref.console_errors:
        name = code(v.name) + (f'<span id="{anchor(v.name)}"></span>' if anchors else "")
        rows.append(
            [str(v.value), name, esc(ref.console_error_texts[v.value]), rich(v.doc, {}, ref.names) if v.doc else "-"]
        )
    out += table(["Code", "Name", "Text", "Cause"], rows)
    return out


def prose(paras: list[tuple[str, str]]) -> list[str]:
    out = []
    for kind, text in paras:
        if kind == "pre":
            if "```" in text:
                raise GenError("a layout block holds ```")
            out += ["```text", text, "```", ""]
        else:
            text = rich(text, {})
            # not a list or a quote
            text = re.sub(r"^([-+>])(?=\s)", r"\\\1", text)
            text = re.sub(r"^(\d+)\.(?=\s)", r"\1\\.", text)
            out += [text, ""]
    return out


def page_console(ref: Reference) -> str:
    c = ref.console
    out = ["# Console protocol", ""]
    out += generated_banner([CONSOLE_H, CONSOLE_REQUEST_C, CONSOLE_PY])
    out += ["## Framing", ""]
    out += prose(c.prose_before)
    if c.constants:
        out += table(
            ["Constant", "Value", "Meaning"],
            [[code(n), code(re.sub(r"(?<=[0-9A-Fa-f])[uU]$", "", v)), esc(d) if d else "-"] for n, v, d in c.constants],
        )
        out.append("")
    out += [
        "## Requests",
        "",
        f"One row per entry of the request table ({code('requests[]')} in {code(CONSOLE_REQUEST_C)}), with "
        f"the DATA layout and the reply as the header describes them. **Reply TYPE** is the request's "
        f"{code('TYPE | 0x80')}. **Needs**: what the image must have, else the error reply named. "
        f"**DATA bytes**: the lengths accepted (else {code('BAD_LENGTH')}).",
        "",
    ]
    rows = []
    for r in c.requests:
        needs = (
            "-"
            if r.needs == "NEEDS_NOTHING"
            else code(r.needs) + (f": {rich(r.needs_text, {})}" if r.needs_text else "")
        )
        length = str(r.min_length) if r.min_length == r.max_length else f"{r.min_length} to {r.max_length}"
        data = "-" if r.data == "-" else rich(r.data, {})
        rows.append(
            [
                code(f"0x{r.code:02X}"),
                code(r.name),
                code(f"0x{r.code | 0x80:02X}"),
                needs,
                length,
                data,
                rich(r.reply, {}),
            ]
        )
    out += table(["TYPE", "Request", "Reply TYPE", "Needs", "DATA bytes", "DATA", "Reply"], rows)
    out.append("")
    for r, other in c.shared_replies:
        out += [
            '!!! warning "A reply TYPE that another frame has too"',
            f"    The reply to {code(r.name)} has TYPE {code(f'0x{r.code | 0x80:02X}')}, which is also the TYPE of "
            f"{code(other)}: a client cannot tell the two apart by TYPE alone.",
            "",
        ]
    if c.other_types:
        out += ["Frame types that are not requests (sent by the drive):", ""]
        out += table(["TYPE", "Name"], [[code(f"0x{v.value:02X}"), code(v.name)] for v in c.other_types])
        out.append("")
    out += prose(c.prose_after)
    out += ["## Error replies", ""]
    out += console_errors_section(ref, anchors=False)
    out.append("")
    return "\n".join(out)


def range_text(k: ScenarioKey) -> str:
    lo = "(" if k.min_exclusive else "["
    hi = ")" if k.max_exclusive else "]"
    return f"{lo}{fmt_number(k.min)}, {fmt_number(k.max)}{hi}"


def page_scenario(ref: Reference) -> str:
    s = ref.scenario
    out = ["# Scenario keys", ""]
    out += generated_banner(
        [SCENARIO_KEYS_C, SCENARIO_KEYS_H] + (["pmstep-sil --print-scenario"] if s.defaults_from else [])
    )
    big = fmt_number(float(s.big))
    out += [
        f"Every key of a {code('pmstep-sil')} scenario: an INI file ({code('--scenario FILE')}) on top of the "
        f"built-in paper scenario, and {code('--set section.key=value')} overrides. "
        f"{code('pmstep-sil --print-scenario')} writes them all with their values. A key's section is its "
        f"name up to the last dot ({code('[controller.motor]')} holds {code('resistance_Ohm')}).",
        "",
        "**Range**: the values the reader accepts, `[` and `]` inclusive ends, `(` and `)` exclusive. "
        f"{esc(big)} is the table's stand-in for no bound: the firmware's own settings "
        f"({code('controller.*')}) take any finite value there and are checked by the firmware's init "
        "(see [Configuration](configuration.md)). A float32 key is a setting of the firmware, of its type: "
        "0 or a normal float32.",
        "",
    ]
    if s.defaults_from:
        out += [
            f"**Paper**: the value in the built-in paper scenario (from {code('pmstep-sil --print-scenario')}).",
            "",
        ]
    sections: dict[str, list[ScenarioKey]] = {}
    for k in s.keys:
        sections.setdefault(k.name.rpartition(".")[0], []).append(k)
    headers = ["Key", "Type", "Range"] + (["Paper"] if s.defaults_from else []) + ["Meaning"]
    for section, keys in sections.items():
        out += [f"## [{section}]", ""]
        rows = []
        for k in keys:
            if k.type in s.enums:
                type_text = "one of " + ", ".join(code(v) for v in s.enums[k.type])
                rng = "-"
            else:
                type_text = esc(KEY_TYPES[k.type])
                rng = code(range_text(k)) if k.type in RANGED_KEY_TYPES else "-"
            row = [code(k.name), type_text, rng]
            if s.defaults_from:
                row.append(code(k.default) if k.default else "-")
            row.append(esc(k.help))
            rows.append(row)
        out += table(headers, rows)
        out.append("")
    out += [
        "## Enumerated values",
        "",
        f"The values of the enumerated key types ({code(SCENARIO_KEYS_H)}), in the order of the C enums "
        "they stand for.",
        "",
    ]
    rows = []
    for t, values in s.enums.items():
        users = [k.name for k in s.keys if k.type == t]
        rows.append(
            [
                code(t),
                code(s.enum_arrays[t]),
                ", ".join(code(v) for v in values),
                "<br>".join(code(u) for u in users) if users else "-",
            ]
        )
    out += table(["Key type", "Names", "Values", "Keys"], rows)
    out.append("")
    return "\n".join(out)


PAGES = {
    "configuration.md": page_configuration,
    "codes.md": page_codes,
    "console-protocol.md": page_console,
    "scenario-keys.md": page_scenario,
}


# ---------------------------------------------------------------------------------------------------
# Tables in hand-written pages
# ---------------------------------------------------------------------------------------------------


@dataclass
class PinUse:
    function: str  # "STEP input"
    signal: str  # "TIM4_CH2", "GPIO input"
    field: str  # the member of step_input: step_pin
    pin: str  # PB7
    af: int
    line: int


def parse_stepdir_pins(board_c: Source) -> list[PinUse]:
    """The STEP/DIR rows of pmstep_stm32g4_pin_map() (`all[n++] = (pmstep_stm32g4_pin_use_t){"FUNCTION",
    "SIGNAL", 0u, cfg->step_input.FIELD};`, in order) with the pins pmstep_stm32g4_default_config() gives
    those fields (`c.step_input.FIELD = (pmstep_stm32g4_pin_t){PORT, PIN, AF};`)."""
    ports = {}
    for line in board_c.lines:
        m = re.match(r"^#define (P[A-G]) (\d+)u\s*$", line)
        if m:
            ports[m.group(1)] = int(m.group(2))
    defaults = {}
    for i, line in enumerate(board_c.lines):
        m = re.match(r"^\s*c\.step_input\.(\w+_pin) = \(pmstep_stm32g4_pin_t\)\{(P[A-G]), (\d+)u, (\d+)u\};", line)
        if m:
            if m.group(2) not in ports:
                raise board_c.error(i, f"port {m.group(2)} not defined")
            defaults[m.group(1)] = (f"{m.group(2)}{int(m.group(3))}", int(m.group(4)))
        elif re.match(r"^\s*c\.step_input\.\w+_pin = ", line):
            raise board_c.error(i, f"step_input pin line not understood: {line.strip()!r}")
    rows = []
    for i, line in enumerate(board_c.lines):
        if "cfg->step_input." not in line or "pmstep_stm32g4_pin_use_t" not in line:
            continue
        m = re.match(
            r'^\s*all\[n\+\+\] = \(pmstep_stm32g4_pin_use_t\)\{"([^"]+)", "([^"]+)", 0u, '
            r"cfg->step_input\.(\w+)\};\s*$",
            line,
        )
        if not m:
            raise board_c.error(i, f"STEP/DIR pin map row not understood: {line.strip()!r}")
        if m.group(3) not in defaults:
            raise board_c.error(i, f"step_input.{m.group(3)} has no pin in pmstep_stm32g4_default_config()")
        pin, af = defaults[m.group(3)]
        rows.append(PinUse(m.group(1), m.group(2), m.group(3), pin, af, i + 1))
    if not rows:
        raise GenError(f"{board_c.name}: no STEP/DIR row (cfg->step_input.*) in pmstep_stm32g4_pin_map()")
    return rows


def pin_mode(use: PinUse) -> str:
    """The pin's mode as the pin table prints it (hal/stm32g4/tools/print_pin_map.c): its alternate function,
    or the GPIO's direction."""
    gpio = {"GPIO input": "input", "GPIO output": "output", "GPIO open drain": "open drain"}
    if use.signal.startswith("GPIO"):
        if use.signal not in gpio:
            raise GenError(f"{STM32G4_BOARD_C}:{use.line}: GPIO signal {use.signal!r} not known to the generator")
        return gpio[use.signal]
    return f"AF{use.af}"


def table_stm32g4_stepdir_pins(root: Path) -> list[str]:
    rows = [
        [esc(u.function), u.pin, esc(u.signal), pin_mode(u), code(f"step_input.{u.field}")]
        for u in parse_stepdir_pins(Source(root, STM32G4_BOARD_C))
    ]
    return table(["Signal", "Pin", "MCU signal", "Mode", "Pin setting"], rows)


# page (relative to --docs) -> table name -> (what it is written from, renderer)
PAGE_TABLES = {
    "getting-started/nucleo-g431rb.md": {
        "stm32g4-stepdir-pins": ([STM32G4_BOARD_C], table_stm32g4_stepdir_pins),
    },
}


def table_markers(name: str, sources: list[str]) -> tuple[str, str]:
    begin = (
        f"<!-- Generated by tools/gen_reference.py ({name}) from {', '.join(sources)}: do not edit down to "
        "the end marker; edit the sources and run it again. -->"
    )
    return begin, f"<!-- End of the table generated by tools/gen_reference.py ({name}). -->"


def fill_tables(text: str, page: str, root: Path) -> str:
    """@p text (the page @p page) with each of its PAGE_TABLES written again between its markers."""
    for name, (sources, render) in PAGE_TABLES[page].items():
        begin, end = table_markers(name, sources)
        if text.count(begin) != 1 or text.count(end) != 1:
            raise GenError(
                f"{page}: the markers of the generated table {name} must be there once each:\n  {begin}\n  {end}"
            )
        head, rest = text.split(begin, 1)
        if end not in rest:
            raise GenError(f"{page}: the end marker of the generated table {name} comes before its start")
        tail = rest.split(end, 1)[1]
        text = head + begin + "\n\n" + "\n".join(render(root)) + "\n\n" + end + tail
    return text


def render_page_tables(root: Path, docs_dir: Path) -> dict[Path, tuple[str, str]]:
    """Each page of PAGE_TABLES in @p docs_dir: (its text, its text with the tables written again)."""
    texts = {}
    for page in PAGE_TABLES:
        path = docs_dir / page
        try:
            old = path.read_text(encoding="utf-8")
        except OSError as e:
            raise GenError(f"{path}: cannot read: {e}") from e
        texts[path] = (old, fill_tables(old, page, root))
    return texts


def write_page_tables(texts: dict[Path, tuple[str, str]]) -> list[Path]:
    """Writes the pages render_page_tables() gave, each only if it changes."""
    written = []
    for path, (old, new) in texts.items():
        if new != old:
            path.write_text(new, encoding="utf-8")
            written.append(path)
    return written


def write_pages(ref: Reference, out_dir: Path) -> list[Path]:
    texts = {name: render(ref) for name, render in PAGES.items()}  # all rendered before any is written
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for name, text in texts.items():
        path = out_dir / name
        path.write_text(text, encoding="utf-8")
        written.append(path)
    return written


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=ROOT / "docs" / "reference",
        help="folder of the pages (default: docs/reference of this tree)",
    )
    parser.add_argument(
        "--docs",
        type=Path,
        default=ROOT / "docs",
        help="folder of the hand-written pages with generated tables (default: docs/ of this tree)",
    )
    parser.add_argument(
        "--sil",
        type=Path,
        default=None,
        help="a pmstep-sil binary: cross-check the scenario keys against its --print-scenario "
        "and add the paper scenario's values",
    )
    parser.add_argument(
        "--parsed-sources",
        action="store_true",
        help="print the C sources whose layout this generator parses, one a line, and exit",
    )
    args = parser.parse_args(argv)
    if args.parsed_sources:
        print("\n".join(PARSED_C_SOURCES))
        return 0
    try:
        ref = load(ROOT, args.sil)
        page_tables = render_page_tables(ROOT, args.docs)  # before any page is written
        written = write_pages(ref, args.out)
        tables = write_page_tables(page_tables)
    except GenError as e:
        print(f"gen_reference: error: {e}", file=sys.stderr)
        return 1
    for n in ref.notes:
        note(n)
    for path in written:
        print(f"gen_reference: wrote {rel(path)}")
    for path in tables:
        print(f"gen_reference: wrote the generated tables of {rel(path)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
