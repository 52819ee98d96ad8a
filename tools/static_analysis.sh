#!/usr/bin/env bash
# Static analysis of the control core (firmware/): zero findings expected.
#   tools/static_analysis.sh analyzer   gcc -fanalyzer with the core's flags, warnings as errors
#   tools/static_analysis.sh cppcheck   cppcheck (warning, style, performance, portability;
#                                        inconclusive included); accepted findings only in
#                                        tests/static/cppcheck_suppressions.txt, each with why
# MISRA C:2012 is tools/misra_check.py (against tests/static/misra_deviations.txt).
set -euo pipefail
cd "$(dirname "$0")/.."
sources=(firmware/src/*.c)
case ${1:-} in
  analyzer)
    command -v gcc >/dev/null || { echo "static_analysis: gcc missing"; exit 2; }
    for f in "${sources[@]}"; do
      gcc -std=c99 -fanalyzer -Wall -Wextra -Wpedantic -Wconversion -Wshadow -Wdouble-promotion -Werror \
          -ffp-contract=off -fno-math-errno -Ifirmware/include -Ifirmware/src -c "$f" -o /dev/null
    done
    echo "static_analysis: gcc -fanalyzer: ${#sources[@]} files of firmware/src, 0 findings"
    ;;
  cppcheck)
    command -v cppcheck >/dev/null || { echo "static_analysis: cppcheck not installed (tools/install_deps.sh): skipped"; exit 77; }
    # unusedFunction is off: the core is a library, its API is called by the application.
    # missingIncludeSystem: the C library's headers are not analysed.
    suppress=()
    while read -r line; do suppress+=("--suppress=$line"); done < <(grep '^[A-Za-z]' tests/static/cppcheck_suppressions.txt || true)
    out=$(cppcheck --enable=warning,style,performance,portability --inconclusive --std=c99 --quiet \
            --error-exitcode=1 --inline-suppr --suppress=missingIncludeSystem \
            "${suppress[@]}" \
            --template='{file}:{line}: {severity}: {message} [{id}]' \
            -Ifirmware/include -Ifirmware/src "${sources[@]}" 2>&1) || { echo "$out"; echo "static_analysis: cppcheck: findings above"; exit 1; }
    accepted=${#suppress[@]}
    echo "static_analysis: cppcheck $(cppcheck --version | cut -d' ' -f2): ${#sources[@]} files of firmware/src, 0 findings ($accepted accepted in tests/static/cppcheck_suppressions.txt)"
    ;;
  *) echo "usage: tools/static_analysis.sh analyzer|cppcheck" >&2; exit 2 ;;
esac
