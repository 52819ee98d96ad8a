"""The header every measured report in docs/reports/ starts with: what wrote it, the command (paths
relative to the repository), the commit and the date, so that a figure can be traced and
regenerated. Reports are written by the tools that measure; never edited by hand."""

import datetime
import os
import re
import shlex
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
REPORTS = os.path.join(ROOT, "docs", "reports")


# The reports themselves: a run of several tools (tools/write_reports.sh) changes them one after
# another, which is no change of what they measure.
REPORTS_PATHSPEC = ":(exclude)docs/reports"


def commit():
    """The commit of the working tree (with '+' when it has changes outside docs/reports), or 'unknown'."""
    try:
        head = subprocess.run(
            ["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=True
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no", "--", ".", REPORTS_PATHSPEC],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        return head + ("+" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def _relative(arg):
    """@p arg with any absolute path inside the repository made relative to it."""
    parts = arg.split("=", 1)
    value = parts[-1]
    if os.path.isabs(value) and os.path.abspath(value).startswith(ROOT + os.sep):
        value = os.path.relpath(value, ROOT)
    elif os.path.exists(value) and not os.path.isabs(value):
        value = os.path.relpath(os.path.abspath(value), ROOT)
    return value if len(parts) == 1 else parts[0] + "=" + value


def command(argv):
    """The command line @p argv as run from the repository's root."""
    return " ".join(shlex.quote(_relative(a)) for a in argv)


def header(title, tool, argv, what=""):
    """The report's first lines: @p title, the @p tool that wrote it, @p argv, commit and date, and
    @p what (a paragraph on what the figures are)."""
    return _provenance(
        f"# {title}", f"Written by `{tool}`; regenerate it with the command below, never edit it by hand.", argv, what
    )


def _provenance(heading, written_by, argv, what):
    """@p heading, @p written_by, then the command, commit and date, and @p what."""
    lines = [
        heading,
        "",
        written_by,
        "",
        f"- command: `{command(argv)}`",
        f"- commit: `{commit()}`",
        f"- date: {datetime.date.today().isoformat()}",
        "",
    ]
    if what:
        lines += [what, ""]
    return "\n".join(lines)


def write(path, text):
    """Writes @p text to @p path (its folder made); returns the path."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text if text.endswith("\n") else text + "\n")
    return path


# ---- pages written section by section (several campaigns, or several tools, on one page) ----
_SECTION = re.compile(r"^<!-- section: ([A-Za-z0-9._-]+) -->\n(.*?)^<!-- end of section: \1 -->\n?", re.M | re.S)


def section_header(heading, tool, argv, what="", level=2):
    """A section's first lines, as header() gives a page's: @p heading, the @p tool, @p argv,
    commit and date, and @p what."""
    return _provenance(f"{'#' * level} {heading}", f"Written by `{tool}`:", argv, what)


def page_header(title, what=""):
    """The first lines of a page written section by section: each section names its command,
    commit and date (section_header())."""
    lines = [
        f"# {title}",
        "",
        "Written section by section by the tools each section names; regenerate a section with its "
        "command, never edit this page by hand.",
        "",
    ]
    if what:
        lines += [what, ""]
    return "\n".join(lines)


def sections(text):
    """The sections of a page written by write_section(): [(name, text)] in page order."""
    return [(m.group(1), m.group(2)) for m in _SECTION.finditer(text)]


def write_section(path, title, name, text, what="", order=()):
    """Writes section @p name of the page at @p path (made if missing) with @p text, replacing that
    section if the page has it, else adding it after the others (or, for a name in @p order, at its
    place in @p order); the page's header (page_header(@p title, @p what)) is written anew and
    nothing outside the sections is kept. Returns the path."""
    if not re.fullmatch(r"[A-Za-z0-9._-]+", name):
        raise ValueError(f"section name {name!r}: letters, digits, '.', '_' and '-' only")
    try:
        with open(path, encoding="utf-8") as f:
            found = sections(f.read())
    except FileNotFoundError:
        found = []
    body = text.rstrip("\n") + "\n\n"  # a blank line: the end marker never joins a table or paragraph
    if any(n == name for n, _ in found):
        found = [(n, body if n == name else t) for n, t in found]
    else:
        found.append((name, body))
    rank = {n: i for i, n in enumerate(order)}
    found.sort(key=lambda nt: rank.get(nt[0], len(rank)))  # stable: the others keep their order
    parts = [page_header(title, what)]
    for n, t in found:
        parts.append(f"<!-- section: {n} -->\n{t}<!-- end of section: {n} -->\n")
    return write(path, "\n".join(parts))
