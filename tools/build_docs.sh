#!/usr/bin/env bash
# Builds the documentation site into build/site, in one command:
#   1. tools/gen_reference.py writes the reference pages generated from the code's tables
#      (docs/reference/configuration.md, codes.md, console-protocol.md, scenario-keys.md; not
#      committed, see .gitignore), and the tables it generates inside committed pages between
#      their markers (the NUCLEO page's STEP/DIR pins; rewritten only when the code changed them);
#   2. Doxygen (docs/Doxyfile) writes the C API reference of the public headers into docs/api/
#      (generated, in .gitignore), which mkdocs copies into the site as api/; any Doxygen warning
#      fails the build;
#   3. .venv/bin/mkdocs build --strict writes the site (mkdocs.yml) into build/site; any mkdocs
#      warning (a broken link or anchor, a page missing from the nav or a nav entry without its
#      page) fails the build.
# Needs doxygen (tools/install_deps.sh) and mkdocs-material in .venv (tools/setup_venv.sh); when
# one of them is missing it says so and exits 77, the code ctest reads as "skipped" (docs.build).
# Serve the result with: .venv/bin/python -m http.server -d build/site  (or .venv/bin/mkdocs serve
# after a first build, for editing).
set -euo pipefail
cd "$(dirname "$0")/.."

skip() { echo "build_docs: $*" >&2; exit 77; }
command -v doxygen >/dev/null 2>&1 || skip "doxygen is not installed: run tools/install_deps.sh"
[ -x .venv/bin/mkdocs ] || skip "no .venv/bin/mkdocs: run tools/setup_venv.sh (mkdocs, mkdocs-material from tools/requirements.txt)"

echo "== reference pages from the code (tools/gen_reference.py)"
if [ ! -f tools/gen_reference.py ]; then
  echo "build_docs: tools/gen_reference.py is missing: it writes docs/reference/configuration.md," \
       "codes.md, console-protocol.md and scenario-keys.md, which the site's nav needs" >&2
  exit 1
fi
.venv/bin/python tools/gen_reference.py

echo "== C API reference (doxygen docs/Doxyfile -> docs/api)"
rm -rf docs/api
if ! doxygen docs/Doxyfile; then
  echo "build_docs: doxygen failed (docs/Doxyfile: every warning is an error; fix the header comments above)" >&2
  exit 1
fi
[ -f docs/api/index.html ] || { echo "build_docs: doxygen wrote no docs/api/index.html" >&2; exit 1; }

echo "== site (mkdocs build --strict -> build/site)"
export NO_MKDOCS_2_WARNING=1  # mkdocs-material 9.8's end-of-life banner: noise in every log
if ! .venv/bin/mkdocs build --strict; then
  echo "build_docs: mkdocs build --strict failed (each WARNING above is an error)" >&2
  exit 1
fi
echo "build_docs: build/site/index.html"
