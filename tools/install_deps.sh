#!/usr/bin/env bash
# Installs the Debian packages the build and tests need, only those missing.
# Usage: tools/install_deps.sh [extra packages]   (as root, or with sudo available)
set -euo pipefail

packages=(
  cmake ninja-build gcc g++ pkg-config     # host build
  libcmocka-dev                            # C unit tests
  libinih-dev libcjson-dev                 # SIL scenario files (INI) and JSON summaries
  libgsl-dev                               # SIL measurement chain: random number generator (MT19937, Gaussian)
  gcc-arm-none-eabi libnewlib-arm-none-eabi binutils-arm-none-eabi  # Cortex-M4F build
  qemu-system-arm                          # processor-in-the-loop on an emulated Cortex-M4
  python3                                  # benchmark scripts (tools/bench_sil.py, tools/bench_target.py)
  libeigen3-dev libboost-dev               # C++ test oracle and gain checker
  clang llvm                               # libFuzzer harnesses (tests/fuzz), llvm-cov for their coverage
  frama-c-base                             # proof of absence of runtime errors (Frama-C EVA, tests/eva)
  cppcheck                                 # static analysis and the MISRA C:2012 addon (tests/static)
  clang-format-14                          # the C sources' format (.clang-format; ctest static.clang_format): one major, one output
  doxygen                                  # C API reference of the public headers (docs/Doxyfile, tools/build_docs.sh)
  chromium                                 # headless screenshots of the built documentation site (tests/docs: docs.render)
  "$@"
)

# libFuzzer ships apart from clang on Debian (libclang-rt-<major>-dev): asked for once clang is there.
libfuzzer_package() {
  command -v clang >/dev/null 2>&1 || return 0
  local probe major
  probe=$(mktemp -d)
  echo 'int LLVMFuzzerTestOneInput(const unsigned char *d, unsigned long n) { (void)d; (void)n; return 0; }' > "$probe/p.c"
  if ! clang -fsanitize=fuzzer "$probe/p.c" -o "$probe/p" 2>/dev/null; then
    major=$(clang -dumpversion | cut -d. -f1)
    echo "libclang-rt-$major-dev"
  fi
  rm -rf "$probe"
}
extra=$(libfuzzer_package)
[ -n "$extra" ] && packages+=("$extra")

missing=()
for pkg in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$pkg")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install_deps: installing ${missing[*]}"
if [ "$(id -u)" -eq 0 ]; then
  SUDO=""
elif command -v sudo >/dev/null 2>&1; then
  SUDO="sudo"
else
  echo "install_deps: not root and no sudo; run: apt-get install ${missing[*]}" >&2
  exit 1
fi
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
if [ -z "$extra" ]; then
  extra=$(libfuzzer_package)
  if [ -n "$extra" ]; then
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "$extra" >/dev/null
  fi
fi
echo "install_deps: done"
