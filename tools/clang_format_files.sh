#!/bin/sh
# Lists the C sources the formatter checks (ctest static.clang_format): every tracked .c and .h
# but the sources whose layout tools/gen_reference.py reads to write the reference pages
# (gen_reference.py --parsed-sources): their enums, tables and comments are that generator's input,
# line by line, and stay as it parses them.
cd "$(dirname "$0")/.." || exit 2
parsed=$(python3 tools/gen_reference.py --parsed-sources) || exit 2
git ls-files '*.c' '*.h' | grep -v -x -F "$parsed"
