"""Tests of tools/gen_reference.py (python3 -m unittest -v test_gen_reference, from tools/).

The generator runs on the real sources into a temporary folder; the pages are checked against
counts and names taken from the sources with simple, independent regular expressions. Copies of
the sources, broken on purpose, check that the parser and the consistency checks fail loudly.
PMSTEP_SIL=<pmstep-sil> also runs the --sil cross-check against that binary.
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import tools_path  # tools/ on the import path
import gen_reference as gen

ROOT = Path(tools_path.ROOT)
GEN = ROOT / "tools" / "gen_reference.py"


def read(relpath):
    return (ROOT / relpath).read_text(encoding="utf-8")


def split_cells(row):
    """The cells of a Markdown table row: split on the pipes outside code spans and not escaped."""
    row = re.sub(r"`[^`]*`", lambda m: m.group(0).replace("|", "\0"), row.strip())
    cells = re.split(r"(?<!\\)\|", row)[1:-1]
    return [c.strip().replace("\0", "|") for c in cells]


def tables(page):
    """Every table of a page: (header cells, [row cells])."""
    out = []
    lines = page.split("\n")
    i = 0
    while i < len(lines):
        if lines[i].startswith("| ") and i + 1 < len(lines) and re.fullmatch(r"\|(---\|)+", lines[i + 1]):
            header = split_cells(lines[i])
            rows = []
            i += 2
            while i < len(lines) and lines[i].startswith("| "):
                rows.append(split_cells(lines[i]))
                i += 1
            out.append((header, rows))
        else:
            i += 1
    return out


def section(page, heading):
    """The text of a page from the heading (a line starting with it) to the next ## heading."""
    start = page.index("\n" + heading) + 1
    end = page.find("\n## ", start + 1)
    return page[start:] if end < 0 else page[start:end]


def block_struct(text, name):
    """The body of `typedef struct { ... } name;` in @p text."""
    return re.search(r"typedef struct \{\n((?:(?!typedef struct).)*?)\n\} " + name + ";", text, re.S).group(1)


def block(text, opening):
    """The lines of a C table from the line matching @p opening to its '};'."""
    lines = text.split("\n")
    start = next(i for i, line in enumerate(lines) if re.match(opening, line))
    end = next(i for i in range(start, len(lines)) if lines[i].strip() == "};")
    return lines[start + 1 : end]


class RealSources(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.out = Path(cls.tmp.name) / "reference"
        cls.docs = Path(cls.tmp.name) / "docs"  # copies of the pages with generated tables
        for page in gen.PAGE_TABLES:
            (cls.docs / page).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(ROOT / "docs" / page, cls.docs / page)
        run = subprocess.run(
            [sys.executable, str(GEN), "--out", str(cls.out), "--docs", str(cls.docs)],
            capture_output=True,
            text=True,
            timeout=120,
        )
        if run.returncode != 0:
            raise AssertionError(f"gen_reference.py failed:\n{run.stdout}\n{run.stderr}")
        cls.pages = {p.name: p.read_text(encoding="utf-8") for p in cls.out.glob("*.md")}
        cls.tabled = {page: (cls.docs / page).read_text(encoding="utf-8") for page in gen.PAGE_TABLES}

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_pages_written_and_marked_generated(self):
        self.assertEqual(set(self.pages), {"configuration.md", "codes.md", "console-protocol.md", "scenario-keys.md"})
        for name, page in self.pages.items():
            self.assertTrue(page.startswith("# "), name)
            self.assertIn("Generated page", page, name)
            self.assertIn("Do not edit", page, name)

    def test_parsed_sources_listed(self):
        """--parsed-sources (the formatter leaves them as written) names every C source the generator reads."""
        read = {v for k, v in vars(gen).items() if k.isupper() and isinstance(v, str) and v.endswith((".c", ".h"))}
        self.assertEqual(set(gen.PARSED_C_SOURCES), read)
        out = subprocess.run(
            [sys.executable, str(GEN), "--parsed-sources"], capture_output=True, text=True, check=True
        ).stdout
        self.assertEqual(out.split(), list(gen.PARSED_C_SOURCES))

    def test_stepdir_pin_table(self):
        """The NUCLEO page's STEP/DIR pin table: one row per STEP/DIR row of pmstep_stm32g4_pin_map(), in its
        order, with the pin pmstep_stm32g4_default_config() gives it, between its markers."""
        board = read(gen.STM32G4_BOARD_C)
        uses = re.findall(r'\{"([^"]+)", "([^"]+)", 0u, cfg->step_input\.(\w+)\}', board)
        self.assertEqual(len(uses), 4)
        pins = {
            f: f"P{p[1]}{n}"
            for f, p, n in re.findall(r"c\.step_input\.(\w+) = \(pmstep_stm32g4_pin_t\)\{(P[A-G]), (\d+)u", board)
        }
        page = self.tabled["getting-started/nucleo-g431rb.md"]
        begin, end = gen.table_markers("stm32g4-stepdir-pins", [gen.STM32G4_BOARD_C])
        between = page.split(begin, 1)[1].split(end, 1)[0]
        [(header, rows)] = tables(between)
        self.assertEqual(header, ["Signal", "Pin", "MCU signal", "Mode", "Pin setting"])
        self.assertEqual(
            [(r[0], r[1], r[2].replace("\\_", "_"), r[4]) for r in rows],
            [(f, pins[field], sig, f"`step_input.{field}`") for f, sig, field in uses],
        )
        self.assertEqual([r[3] for r in rows], ["AF2", "AF2", "input", "open drain"])
        self.assertIn("| STEP input | PB7 |", between)

    def test_committed_pages_have_their_tables_current(self):
        """The committed pages hold what the generator writes: nobody edited a generated table by hand,
        and the sources did not change since it last ran."""
        for page, text in self.tabled.items():
            self.assertEqual(read(f"docs/{page}"), text, f"docs/{page}: run tools/gen_reference.py")

    def test_tables_are_well_formed(self):
        for name, page in self.pages.items():
            found = tables(page)
            self.assertTrue(found, name)
            for header, rows in found:
                self.assertTrue(rows, f"{name}: empty table {header}")
                for row in rows:
                    self.assertEqual(len(row), len(header), f"{name}: {row}")
                    for cell in row:
                        self.assertEqual(cell.count("`") % 2, 0, f"{name}: unbalanced backticks in {cell!r}")

    def test_anchors_linked_exist(self):
        ids = {name: set(re.findall(r'<span id="([^"]+)"></span>', page)) for name, page in self.pages.items()}
        for name, page in self.pages.items():
            for target, anchor in re.findall(r"\]\(([\w-]+\.md)#([^)]+)\)", page):
                self.assertIn(anchor, ids[target], f"{name} links to {target}#{anchor}")

    def configuration_rows(self):
        rows = []
        for header, body in tables(self.pages["configuration.md"]):
            self.assertEqual(header[:2], ["Id", "Setting"])
            rows += [dict(zip(header, r)) for r in body]
        return rows

    def test_configuration_has_every_field_once(self):
        text = read(gen.CONSOLE_CONFIG_C)
        console = [
            line
            for line in block(text, r"^static const pmstep_console_config_entry_t table\[\]")
            if re.match(r"^\s+\w+\([\w.]+\),\s*$", line)
        ]

        def entry_name(line):  # the STEP/DIR settings' entries (SD_*) are named stepdir.<field>
            return ("stepdir." if re.match(r"^\s+SD_", line) else "") + re.search(r"\(([\w.]+)\)", line).group(1)

        console_names = {entry_name(line) for line in console}
        fields = [f.path for g in gen.parse_config_fields(gen.Source(ROOT, gen.TYPES_H)) for f in g.fields]
        fields += [
            "stepdir." + m.group(1)
            for m in re.finditer(
                r"^\s+(?:uint32_t|bool|float) (\w+);",
                block_struct(read(gen.STORE_H), "pmstep_stepdir_settings_t"),
                re.M,
            )
        ]
        unexposed = [f for f in fields if f not in console_names]
        rows = self.configuration_rows()
        self.assertEqual(len(rows), len(console) + len(unexposed))
        names = [re.match(r"`([\w.]+)`", r["Setting"]).group(1) for r in rows]
        self.assertEqual(sorted(names), sorted(fields))
        for r in rows:
            if r["Id"] == "-":
                self.assertEqual(r["Console"], "not exposed")
        # ids are the table's positions
        for cid, line in enumerate(console):
            name = entry_name(line)
            row = next(r for r in rows if r["Setting"].startswith(f"`{name}`"))
            self.assertEqual(row["Id"], str(cid), name)
            self.assertEqual(row["Console"], "read-only" if "_RO(" in line else "read/write", name)

    def row(self, name):
        return next(r for r in self.configuration_rows() if r["Setting"].startswith(f"`{name}`"))

    def test_known_configuration_rows(self):
        r = self.row("limits.max_phase_current_A")
        self.assertEqual(r["Id"], "21")
        self.assertEqual(r["Type"], "`float`")
        self.assertEqual(r["Unit"], "A")
        self.assertEqual(r["Console"], "read/write")
        self.assertTrue(r["Range (init)"].startswith("`> 0`<br>[`PMSTEP_ERR_MAX_CURRENT`]"), r["Range (init)"])
        for c in (
            "PMSTEP_ERR_TRIP_ABOVE_RATED",
            "PMSTEP_ERR_TRIP_ABOVE_SENSE_RANGE",
            "PMSTEP_ERR_ALIGNMENT_CURRENT",
            "PMSTEP_ERR_DEAD_TIME_BAND",
            "PMSTEP_ERR_HOLD_CURRENT",
        ):
            self.assertIn(f"[`{c}`](codes.md#{c.lower()})", r["Range (init)"])
        self.assertIn("`PMSTEP_MAX_TRIP_PER_RATED_CURRENT` (= 3)", r["Range (init)"])
        self.assertIn("FAULT\\_OVERCURRENT", r["Meaning"])

        r = self.row("timing.period_s")
        self.assertEqual((r["Id"], r["Unit"], r["Console"]), ("6", "s", "read-only"))
        self.assertIn("PMSTEP_ERR_PERIOD", r["Range (init)"])
        self.assertNotIn("`> 0`", r["Range (init)"])  # SIGN_ANY: checked by range
        r = self.row("motor.friction_Nms_rad")
        self.assertEqual(r["Unit"], "Nm s/rad")
        self.assertTrue(r["Range (init)"].startswith("`>= 0`<br>[`PMSTEP_ERR_FRICTION`]"))
        r = self.row("motor.torque_constant_Nm_A")
        self.assertEqual(r["Unit"], "Nm/A")
        r = self.row("motor.pole_pairs")
        self.assertEqual((r["Type"], r["Unit"]), ("`int32_t`", "-"))
        self.assertIn("PMSTEP_ERR_POLE_PAIRS", r["Range (init)"])
        r = self.row("gains.current_integral_gain_per_s2")
        self.assertEqual(r["Unit"], "1/s^2")
        r = self.row("commissioning.use_measured_resistance")
        self.assertIn("PMSTEP_ERR_RESISTANCE_UNMEASURED", r["Range (init)"])
        self.assertNotIn("PMSTEP_ERR_RESISTANCE_UNMEASURED", self.row("motor.resistance_Ohm")["Range (init)"])
        r = self.row("known_load_mode")
        self.assertIn("PMSTEP_ERR_STANDSTILL_KNOWN_LOAD", r["Range (init)"])
        # grouped by sub-structure, in pmstep_config_t's order, the top level last
        headings = re.findall(r"^## (.+)$", self.pages["configuration.md"], re.M)
        self.assertEqual(
            headings,
            [
                "motor",
                "timing",
                "alignment",
                "gains",
                "limits",
                "commissioning",
                "inverter",
                "detection",
                "standstill",
                "field_weakening",
                "Top level",
                "stepdir",
            ],
        )

    def test_stepdir_rows(self):
        """The STEP/DIR settings after the core's, each with the codes pmstep_console_stepdir_validate()
        refuses it with."""
        r = self.row("stepdir.microsteps")
        self.assertEqual((r["Type"], r["Unit"], r["Console"]), ("`uint32_t`", "-", "read/write"))
        self.assertTrue(
            r["Range"].startswith("[`PMSTEP_ERR_STEPDIR_MICROSTEPS`](codes.md#pmstep_err_stepdir_microsteps)"),
            r["Range"],
        )
        r = self.row("stepdir.diag_mode")
        self.assertIn("PMSTEP_ERR_STEPDIR_DIAG_MODE", r["Range"])
        self.assertNotIn("PMSTEP_ERR_STEPDIR_MICROSTEPS", r["Range"])
        r = self.row("stepdir.following_error_limit_full_steps")
        self.assertEqual((r["Type"], r["Unit"]), ("`float`", "full steps"))
        self.assertTrue(r["Range"].startswith("[`PMSTEP_ERR_STEPDIR_LIMIT`]"), r["Range"])
        for name in ("stepdir.invert_direction", "stepdir.enable_active_high", "stepdir.diag_active_high"):
            self.assertEqual(self.row(name)["Range"], "any")
        # the console's ids follow the core's: the table's last entries
        ids = sorted(int(self.row(n)["Id"]) for n in ("stepdir.microsteps", "stepdir.following_error_limit_full_steps"))
        self.assertEqual(ids[1] - ids[0], 5)
        # the codes page names the setting of each STEP/DIR code
        codes = self.pages["codes.md"]
        line = next(x for x in codes.split("\n") if "`PMSTEP_ERR_STEPDIR_DIAG_MODE`" in x and x.startswith("| -138"))
        self.assertIn("configuration.md#cfg-stepdir-diag_mode", line)

    def test_every_status_code_once_with_its_text(self):
        types_h = read(gen.TYPES_H)
        body = types_h[types_h.index("typedef enum {") : types_h.index("} pmstep_status_t;")]
        codes = re.findall(r"^\s+(PMSTEP_\w+) = (-?\d+)", body, re.M)
        self.assertGreater(len(codes), 50)
        texts = dict(re.findall(r'case (PMSTEP_\w+):\s*return "([^"]*)";', read(gen.TEXT_C)))
        ((header, rows),) = tables(section(self.pages["codes.md"], "## Status codes"))
        self.assertEqual(header[:4], ["Code", "Name", "Text", "Cause"])
        for name, value in codes:
            hits = [r for r in rows if r[1].startswith(f"`{name}`")]
            self.assertEqual(len(hits), 1, name)
            self.assertEqual(hits[0][0], value, name)
            self.assertTrue(hits[0][2] and hits[0][2] != "-", name)
            self.assertEqual(hits[0][2], gen.esc(texts[name]), name)
        self.assertEqual(len(rows), len(codes))

    def test_other_code_tables(self):
        page = self.pages["codes.md"]
        types_h = read(gen.TYPES_H)
        for heading, enum in (
            ("## Fault codes", "pmstep_fault_t"),
            ("## Modes", "pmstep_mode_t"),
            ("## Identification outcomes", "pmstep_identification_t"),
        ):
            body = types_h[: types_h.index(f"}} {enum};")]
            body = body[body.rindex("typedef enum {") :]
            names = re.findall(r"^\s+(PMSTEP_\w+) = \d+", body, re.M)
            ((_, rows),) = tables(section(page, heading))
            self.assertEqual([re.match(r"`(\w+)`", r[1]).group(1) for r in rows], names, heading)
        console_h = read(gen.CONSOLE_H)
        errors = re.findall(r"^\s+(PMSTEP_CONSOLE_ERR_\w+) = (\d+)", console_h, re.M)
        ((_, rows),) = tables(section(page, "## Console error replies"))
        self.assertEqual([(re.match(r"`(\w+)`", r[1]).group(1), r[0]) for r in rows], errors)
        stm32 = re.findall(r"^\s+(PMSTEP_STM32G4_(?:OK|ERR_\w+)) = ", read(gen.STM32G4_H), re.M)
        ((_, rows),) = tables(section(page, "## STM32G4 port status codes"))
        self.assertEqual([re.match(r"`(\w+)`", r[1]).group(1) for r in rows], stm32)
        self.assertTrue(all(r[2] and r[2] != "-" for r in rows))

    def test_console_protocol(self):
        page = self.pages["console-protocol.md"]
        self.assertIn("0xA5 | LEN | TYPE SEQ DATA", page)
        self.assertIn("CRC-16/CCITT-FALSE", page)
        rows_c = [
            line
            for line in block(read(gen.CONSOLE_REQUEST_C), r"^static const request_row_t requests\[\]")
            if line.strip().startswith("{")
        ]
        (header, rows), (_, others) = tables(section(page, "## Requests"))
        self.assertEqual(header, ["TYPE", "Request", "Reply TYPE", "Needs", "DATA bytes", "DATA", "Reply"])
        self.assertEqual(len(rows), len(rows_c))
        by_name = {r[1].strip("`"): r for r in rows}
        self.assertEqual(by_name["SPEED_TARGET"][:5], ["`0x05`", "`SPEED_TARGET`", "`0x85`", "-", "8"])
        self.assertEqual(by_name["SPEED_TARGET"][5], "target f32, ramp f32")
        self.assertEqual(by_name["GET_CONFIG"][4], "1 to 62")  # NAME_ROOM = MAX_PAYLOAD - 2
        self.assertIn("`PMSTEP_CONSOLE_ERR_NO_POSITION`", by_name["MOVE_TO"][3])
        self.assertEqual(by_name["MOVE_TO"][4], "12 to 16")
        self.assertIn("ACK: status i16, period u32", by_name["STOP"][6])
        self.assertEqual([r[1] for r in others], ["`PMSTEP_CONSOLE_TELEMETRY_FRAME`", "`PMSTEP_CONSOLE_ERROR_FRAME`"])
        ((_, errors),) = tables(section(page, "## Error replies"))
        self.assertEqual(len(errors), len(re.findall(r"^\s+PMSTEP_CONSOLE_ERR_\w+ = \d+", read(gen.CONSOLE_H), re.M)))

    def test_scenario_keys_page_has_every_key(self):
        text = read(gen.SCENARIO_KEYS_C)
        keys = re.findall(r'^\s*\{"([\w.]+)", KEY_\w+,', text, re.M)
        self.assertGreater(len(keys), 100)
        page = self.pages["scenario-keys.md"]
        rows = [r for _, body in tables(page) for r in body]
        key_cells = [r[0] for r in rows if r[0].startswith("`") and "." in r[0] and not r[0].startswith("`KEY_")]
        self.assertEqual(sorted(k.strip("`") for k in key_cells), sorted(keys))
        for k in keys:
            section_name = k.rpartition(".")[0]
            self.assertIn(f"`{k}`", section(page, f"## [{section_name}]"), k)
        self.assertIn("## [controller.motor]", page)
        r = next(r for r in rows if r[0] == "`sensors.gain_error_a`")
        self.assertEqual(r[2], "`(-0.5, 0.5)`")
        r = next(r for r in rows if r[0] == "`run.duration_s`")
        self.assertEqual(r[2], "`(0, 3600]`")
        r = next(r for r in rows if r[0] == "`load.type`")
        self.assertEqual(r[1], "one of `none`, `constant`, `step`, `proportional`, `table`")
        ((_, enums),) = tables(section(page, "## Enumerated values"))
        self.assertEqual(len(enums), len(re.findall(r"_names\[\] = ", read(gen.SCENARIO_KEYS_H))))


class Units(unittest.TestCase):
    def test_suffixes(self):
        self.assertEqual(gen.unit_of("limits.max_phase_current_A", "float"), "A")
        self.assertEqual(gen.unit_of("motor.torque_constant_Nm_A", "float"), "Nm/A")
        self.assertEqual(gen.unit_of("gains.current_integral_gain_per_s2", "float"), "1/s^2")
        self.assertEqual(gen.unit_of("gains.speed_gain_per_s", "float"), "1/s")
        self.assertEqual(gen.unit_of("gains.sat_kappa_rad_s", "float"), "rad/s")
        self.assertEqual(gen.unit_of("timing.computational_delay_periods", "uint32_t"), "control periods")
        self.assertEqual(gen.unit_of("known_load_mode", "bool"), "")
        self.assertEqual(gen.unit_of("motor.pole_pairs", "int32_t"), "")

    def test_unknown_suffix_raises(self):
        with self.assertRaises(gen.GenError) as ctx:
            gen.unit_of("inverter.gate_charge_nC", "float")
        self.assertIn("inverter.gate_charge_nC", str(ctx.exception))
        with self.assertRaises(gen.GenError):
            gen.unit_of("gains.new_ratio", "uint32_t")


class Markdown(unittest.TestCase):
    def test_escape(self):
        self.assertEqual(
            gen.esc("|i_a| <= 2*x [a, b] $5 {c} \\"), "\\|i\\_a\\| &lt;= 2\\*x &#91;a, b&#93; &#36;5 \\{c\\} &#92;"
        )

    def test_code_span_refuses_backtick(self):
        with self.assertRaises(gen.GenError):
            gen.code("a`b")

    def test_numbers(self):
        self.assertEqual(gen.fmt_number(1e12), "1e12")
        self.assertEqual(gen.fmt_number(4294967295.0), "4294967295")
        self.assertEqual(gen.fmt_number(3600.0), "3600")
        self.assertEqual(gen.fmt_number(1e-6), "1e-6")
        self.assertEqual(gen.fmt_number(-0.5), "-0.5")
        self.assertEqual(gen.fmt_number(0.0), "0")


class BrokenSources(unittest.TestCase):
    """The generator on a copy of the sources with one change: it must raise, naming the file."""

    FILES = [
        gen.TYPES_H,
        gen.CONFIG_C,
        gen.TEXT_C,
        gen.CONSOLE_H,
        gen.CONSOLE_CONFIG_C,
        gen.CONSOLE_REQUEST_C,
        gen.CONSOLE_PY,
        gen.STORE_H,
        gen.STM32G4_H,
        gen.STM32G4_BOARD_C,
        "docs/getting-started/nucleo-g431rb.md",
        gen.STM32G4_TEXT_C,
        gen.SCENARIO_KEYS_C,
        gen.SCENARIO_KEYS_H,
    ]

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.root = Path(self.tmp.name)
        for f in self.FILES:
            (self.root / f).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(ROOT / f, self.root / f)

    def tearDown(self):
        self.tmp.cleanup()

    def edit(self, relpath, pattern, replacement):
        """Replaces the one match of the regular expression @p pattern (multi-line) in a copy."""
        path = self.root / relpath
        text, n = re.subn(pattern, replacement, path.read_text(encoding="utf-8"), count=1, flags=re.M)
        self.assertEqual(n, 1, f"{relpath}: no match for {pattern!r}")
        path.write_text(text, encoding="utf-8")

    def assert_fails(self, *fragments):
        with self.assertRaises(gen.GenError) as ctx:
            gen.load(self.root)
        for fragment in fragments:
            self.assertIn(fragment, str(ctx.exception))

    def test_copy_loads(self):
        ref = gen.load(self.root)
        self.assertEqual(len(ref.fields()), len(ref.console_rows))

    def test_code_without_text(self):
        self.edit(gen.TEXT_C, r'^\s*case PMSTEP_ERR_INERTIA:\s*return "[^"]*";\n', "")
        self.assert_fails(gen.TEXT_C, "no text", "PMSTEP_ERR_INERTIA")

    def test_text_without_code(self):
        self.edit(gen.TEXT_C, r"^(\s*switch \(fault\) \{\n)", '\\1    case PMSTEP_FAULT_GONE: return "GONE";\n')
        self.assert_fails("PMSTEP_FAULT_GONE", "not a value of pmstep_fault_t")

    def test_stm32_code_without_text(self):
        self.edit(gen.STM32G4_TEXT_C, r'^\s*case PMSTEP_STM32G4_ERR_PIN_CONFLICT:\s*return "[^"]*";\n', "")
        self.assert_fails(gen.STM32G4_TEXT_C, "PMSTEP_STM32G4_ERR_PIN_CONFLICT")

    def test_table_shape_change(self):
        self.edit(gen.CONFIG_C, r"(SIGN_RULE\(motor\.inertia_kgm2, \w+, \w+)\),", r"\1, 1),")
        self.assert_fails(f"{gen.CONFIG_C}:", "sign_rules[] line not understood")

    def test_console_entry_of_another_type(self):
        self.edit(gen.CONSOLE_CONFIG_C, r"\bI32\(motor\.pole_pairs\)", "F32(motor.pole_pairs)")
        self.assert_fails("motor.pole_pairs", "F32 on the console but int32_t")

    def test_console_entry_naming_no_field(self):
        self.edit(gen.CONSOLE_CONFIG_C, r"\bF32\(motor\.detent_torque_Nm\)", "F32(motor.detent_Nm)")
        self.assert_fails(f"{gen.CONSOLE_CONFIG_C}:", "motor.detent_Nm", "not a field of pmstep_config_t")

    def assert_tables_fail(self, *fragments):
        with self.assertRaises(gen.GenError) as ctx:
            gen.render_page_tables(self.root, self.root / "docs")
        for fragment in fragments:
            self.assertIn(fragment, str(ctx.exception))

    def test_page_tables_of_the_copy(self):
        texts = gen.render_page_tables(self.root, self.root / "docs")
        self.assertEqual({p.relative_to(self.root / "docs").as_posix() for p in texts}, set(gen.PAGE_TABLES))

    def test_pin_map_row_shape_change(self):
        self.edit(gen.STM32G4_BOARD_C, r'(\{"DIR input", "TIM4_CH1", 0u, cfg->step_input\.dir_pin)\}', r"\1, 1}")
        self.assert_tables_fail(f"{gen.STM32G4_BOARD_C}:", "STEP/DIR pin map row not understood")

    def test_pin_map_row_without_default_pin(self):
        self.edit(gen.STM32G4_BOARD_C, r"^\s*c\.step_input\.diag_pin = .*\n", "")
        self.assert_tables_fail(f"{gen.STM32G4_BOARD_C}:", "step_input.diag_pin has no pin")

    def test_table_marker_missing(self):
        self.edit("docs/getting-started/nucleo-g431rb.md", r"^<!-- End of the table generated .*-->\n", "")
        self.assert_tables_fail("nucleo-g431rb.md", "stm32g4-stepdir-pins", "markers")

    def test_stepdir_entry_naming_no_field(self):
        self.edit(gen.CONSOLE_CONFIG_C, r"\bSD_U32\(microsteps\)", "SD_U32(microstep_count)")
        self.assert_fails(
            f"{gen.CONSOLE_CONFIG_C}:", "stepdir.microstep_count", "not a field of pmstep_stepdir_settings_t"
        )

    def test_stepdir_check_of_no_field(self):
        self.edit(gen.CONSOLE_CONFIG_C, r"sd->diag_mode != \(uint32_t\)PMSTEP_DIAG_LEVEL", "sd->mode != 0u")
        self.assert_fails(f"{gen.CONSOLE_CONFIG_C}:", "sd->mode", "pmstep_stepdir_settings_t")

    def test_stepdir_check_with_unknown_code(self):
        self.edit(gen.CONSOLE_CONFIG_C, r"return PMSTEP_ERR_STEPDIR_DIAG_MODE;", "return PMSTEP_ERR_STEPDIR_MODE;")
        self.assert_fails(f"{gen.CONSOLE_CONFIG_C}:", "PMSTEP_ERR_STEPDIR_MODE", "not a value of pmstep_status_t")

    def test_new_field_with_unknown_unit(self):
        self.edit(
            gen.TYPES_H, r"^(\s*)float dead_time_s;", r"\1float gate_charge_nC; /**< new */\n\1float dead_time_s;"
        )
        self.assert_fails("inverter.gate_charge_nC", "unit suffix")

    def test_scenario_row_shape_change(self):
        self.edit(gen.SCENARIO_KEYS_C, r'^(\s*\{"bus\.ripple_Hz", .*)\},\s*$', r"\1, 0},")
        self.assert_fails(f"{gen.SCENARIO_KEYS_C}:", "scenario_keys[] line not understood")

    def test_request_missing_from_header_list(self):
        self.edit(gen.CONSOLE_H, r"^ \*   0x10 SET_POSITION_ZERO .*\n", "")
        self.assert_fails("SET_POSITION_ZERO", "Requests (DATA):")

    def test_stale_phrase(self):
        self.edit(gen.TYPES_H, r"(PMSTEP_ERR_DELAY = -?\d+,\s*/\*\*<\s*)computational delay", r"\1delay")
        self.assert_fails("FIELD_PHRASES", "computational delay")

    def test_host_error_texts_must_match(self):
        self.edit(gen.CONSOLE_PY, r"^(ERRORS = \{)", '\\1 99: "new",')
        self.assert_fails(gen.CONSOLE_PY, "ERRORS")


class SilCrossCheck(unittest.TestCase):
    def fake_sil(self, folder, drop=None):
        """A stand-in for pmstep-sil --print-scenario: the table's keys, or all but @p drop."""
        keys = gen.parse_scenario(gen.Source(ROOT, gen.SCENARIO_KEYS_C), gen.Source(ROOT, gen.SCENARIO_KEYS_H)).keys
        lines = ["[scenario]", "name = paper"]
        section_name = None
        for k in keys:
            if k.name == drop:
                continue
            sec, _, key = k.name.rpartition(".")
            if sec != section_name:
                lines += ["", f"[{sec}]"]
                section_name = sec
            lines += [f"; {k.help}", f"{key} = 1"]
        path = Path(folder) / "fake-sil"
        path.write_text("#!/bin/sh\ncat <<'EOF'\n" + "\n".join(lines) + "\nEOF\n", encoding="utf-8")
        path.chmod(0o755)
        return path

    def test_fake_sil_defaults(self):
        with tempfile.TemporaryDirectory() as d:
            ref = gen.load(ROOT, self.fake_sil(d))
            self.assertTrue(all(k.default == "1" for k in ref.scenario.keys))
            page = gen.page_scenario(ref)
            self.assertIn("| Key | Type | Range | Paper | Meaning |", page)

    def test_fake_sil_missing_key(self):
        with tempfile.TemporaryDirectory() as d:
            with self.assertRaises(gen.GenError) as ctx:
                gen.load(ROOT, self.fake_sil(d, drop="run.seed"))
            self.assertIn("run.seed", str(ctx.exception))

    @unittest.skipUnless(os.environ.get("PMSTEP_SIL"), "PMSTEP_SIL not set")
    def test_real_sil(self):
        ref = gen.load(ROOT, Path(os.environ["PMSTEP_SIL"]))
        self.assertTrue(all(k.default is not None for k in ref.scenario.keys))


if __name__ == "__main__":
    unittest.main()
