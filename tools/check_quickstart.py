#!/usr/bin/env python3
"""Runs the shell blocks of the getting-started pages that are marked for it (ctest docs.quickstart),
so the commands a reader copies keep working.

Marking a block (for page writers): put the HTML comment  <!-- check -->  on the line right
before the opening fence, at the fence's indentation. The comment does not show on the site.

    <!-- check -->
    ```bash
    tools/run_paper.sh
    ```

Rules for a marked block:
  - its language is bash, sh or shell (commands without a "$ " prompt; use a `console` block,
    unmarked, to show a session with its output);
  - it runs as a script of its own, `bash -e FILE`, from the repository root, on the tree as it
    is (build/host-release as built so far: a block that needs the optimised SIL runs
    tools/run_paper.sh or tools/setup_host.sh, which build what is missing); nothing carries over
    from one block to the next but files (no cd, no variables), and stdin is /dev/null;
  - the pages run in the order of the site's nav (mkdocs.yml), so a page may use what an
    earlier one built (the SIL page's tools/run_paper.sh builds build/host-release); the blocks
    of a page run in order, and a page stops at its first failed block;
  - it may not run tools/test_all.sh, the full test command: CI runs it, it runs ctest, and
    ctest runs this check (the checker refuses such a block before running anything);
  - it should finish in minutes (the limit is --timeout, 1800 s a block by default);
  - a block that runs ctest runs this check again inside it: that inner run sees
    PMSTEP_QUICKSTART_BLOCK in its environment and skips itself (77).
Blocks that need hardware (the NUCLEO page's flashing, a serial port) stay unmarked.

  tools/check_quickstart.py [PAGE.md ...]   run the marked blocks (default: docs/getting-started/*.md)
  tools/check_quickstart.py --list          print them without running them

Exit status: 0 all blocks ran; 1 a block failed, or a page is malformed (a marker without a
block, an unterminated fence, a marked block in another language or running tools/test_all.sh),
or the pages have no marked block at all; 77 (ctest: skipped) when there is no getting-started
page yet.
"""

import argparse
import glob
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MARKER = "<!-- check -->"
LANGUAGES = ("bash", "sh", "shell")
FENCE = re.compile(r"^(?P<indent>[ \t]*)(?P<fence>`{3,}|~{3,})[ \t]*(?P<info>[^`]*)$")
FULL_TEST = re.compile(r"(^|[\s;&|()/])test_all\.sh\b")


class PageError(Exception):
    pass


def fence_language(info):
    """The language of a fence's info string: ```bash, ``` bash title="x", ```{.bash ...}."""
    info = info.strip()
    m = re.match(r"^\{\s*\.?([\w+-]+)", info) or re.match(r"^\.?([\w+-]+)", info)
    return m.group(1).lower() if m else ""


def marked_blocks(path):
    """[(line of the fence, 1-based; language; code)] of the marked blocks of a page."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    rel = os.path.relpath(path, ROOT)
    blocks, i = [], 0
    while i < len(lines):
        if lines[i].strip() != MARKER:
            i += 1
            continue
        marker_line, indent = i + 1, lines[i][: len(lines[i]) - len(lines[i].lstrip())]
        i += 1
        m = FENCE.match(lines[i]) if i < len(lines) else None
        if not m:
            raise PageError(f"{rel}:{marker_line}: {MARKER} must be followed, on the next line, by a fenced block")
        if m.group("indent") != indent:
            raise PageError(f"{rel}:{i + 1}: the fence must have the marker's indentation")
        fence, language, start = m.group("fence"), fence_language(m.group("info")), i + 1
        code, i = [], i + 1
        while i < len(lines):
            closing = FENCE.match(lines[i])
            if (
                closing
                and closing.group("fence").startswith(fence)
                and not closing.group("info").strip()
                and closing.group("fence")[0] == fence[0]
            ):
                break
            line = lines[i]
            code.append(line[len(indent) :] if line.startswith(indent) else line.lstrip())
            i += 1
        else:
            raise PageError(f"{rel}:{start}: the marked block's fence is never closed")
        i += 1
        if language not in LANGUAGES:
            raise PageError(
                f"{rel}:{start}: a marked block must be {', '.join(LANGUAGES)} "
                f"(commands without prompts), not {language or 'a block without a language'}"
            )
        text = "\n".join(code).strip("\n") + "\n"
        for n, line in enumerate(code):
            if FULL_TEST.search(line.split("#", 1)[0]):
                raise PageError(
                    f"{rel}:{start + 1 + n}: a checked block may not run tools/test_all.sh, the full "
                    "test command (CI runs it; it runs ctest, which runs this check): leave that "
                    "block unmarked"
                )
        if not text.strip():
            raise PageError(f"{rel}:{start}: the marked block is empty")
        blocks.append((start, language, text))
    return blocks


def nav_order(pages):
    """The pages in the order mkdocs.yml's nav lists them; those it does not list last, by name."""
    try:
        with open(os.path.join(ROOT, "mkdocs.yml"), encoding="utf-8") as f:
            nav = [os.path.join(ROOT, "docs", m) for m in re.findall(r"(getting-started/[\w.-]+\.md)", f.read())]
    except OSError:
        nav = []
    rank = {path: n for n, path in reversed(list(enumerate(nav)))}
    return sorted(pages, key=lambda p: (rank.get(p, len(rank)), p))


def run_block(rel, line, number, count, text, timeout_s):
    """Runs one block with bash -e from the repository root; True when it exits 0."""
    print(f"\n== {rel}:{line} (block {number} of {count})", flush=True)
    for code_line in text.rstrip("\n").split("\n"):
        print(f"   | {code_line}")
    print(flush=True)
    with tempfile.NamedTemporaryFile("w", suffix=".sh", prefix="quickstart-", delete=False) as f:
        f.write(text)
        script = f.name
    started = time.monotonic()
    env = dict(os.environ, PMSTEP_QUICKSTART_BLOCK=f"{rel}:{line}")
    proc = subprocess.Popen(["bash", "-e", script], cwd=ROOT, stdin=subprocess.DEVNULL, env=env, start_new_session=True)
    try:
        rc = proc.wait(timeout=timeout_s)
        reason = f"exit code {rc}"
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        rc, reason = -1, f"still running after {timeout_s:.0f} s (--timeout)"
    finally:
        os.unlink(script)
    elapsed = time.monotonic() - started
    if rc == 0:
        print(f"-- {rel}:{line}: ok ({elapsed:.1f} s)", flush=True)
        return True
    print(f"-- {rel}:{line}: FAILED, {reason}, after {elapsed:.1f} s", flush=True)
    return False


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("pages", nargs="*", help="pages to check (default: docs/getting-started/*.md)")
    parser.add_argument("--list", action="store_true", help="print the marked blocks, run nothing")
    parser.add_argument("--timeout", type=float, default=1800.0, help="seconds a block may take (1800)")
    args = parser.parse_args()

    if os.environ.get("PMSTEP_QUICKSTART_BLOCK"):
        print(f"check_quickstart: inside the block {os.environ['PMSTEP_QUICKSTART_BLOCK']}: not again (skipped)")
        return 77
    pages = [os.path.abspath(p) for p in args.pages] or nav_order(
        glob.glob(os.path.join(ROOT, "docs", "getting-started", "*.md"))
    )
    if not pages:
        print("check_quickstart: no page in docs/getting-started/ yet: nothing to check (skipped)")
        return 77
    try:
        found = [(os.path.relpath(p, ROOT), marked_blocks(p)) for p in pages]
    except (PageError, OSError) as e:
        print(f"check_quickstart: {e}", file=sys.stderr)
        return 1
    total = sum(len(blocks) for _, blocks in found)
    for rel, blocks in found:
        print(f"{rel}: {len(blocks)} marked block(s)")
    if total == 0:
        print(
            f"check_quickstart: no block of {', '.join(rel for rel, _ in found)} is marked {MARKER}: mark the "
            "commands a reader runs (see this script's docstring)",
            file=sys.stderr,
        )
        return 1
    if args.list:
        for rel, blocks in found:
            for line, language, text in blocks:
                print(f"\n{rel}:{line} ({language})\n{text}", end="")
        return 0

    if not os.path.exists(os.path.join(ROOT, "build", "host-release", "sil", "pmstep-sil")):
        print(
            "check_quickstart: note: build/host-release is not built yet; blocks that run tools/run_paper.sh "
            "or tools/setup_host.sh build it first (minutes)"
        )
    failed, not_run = [], []
    for rel, blocks in found:
        for number, (line, _, text) in enumerate(blocks, start=1):
            if not run_block(rel, line, number, len(blocks), text, args.timeout):
                failed.append(f"{rel}:{line} (block {number})")
                not_run += [f"{rel}:{later[0]}" for later in blocks[number:]]
                break
    print()
    if failed:
        print(
            f"check_quickstart: FAILED: {', '.join(failed)}"
            + (f"; not run after it: {', '.join(not_run)}" if not_run else ""),
            file=sys.stderr,
        )
        return 1
    print(f"check_quickstart: all {total} marked block(s) of {len(found)} page(s) ran")
    return 0


if __name__ == "__main__":
    sys.exit(main())
