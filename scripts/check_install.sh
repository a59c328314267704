#!/usr/bin/env bash
# Installs the release build into a temporary prefix, then builds and runs the out-of-tree C++
# example (examples/cpp, find_package(bendlab)) and the Python example (examples/python/figure8.py)
# against that installation only. Run from the repository root after the release build.
set -euo pipefail
cd "$(dirname "$0")/.."
prefix=$(mktemp -d)
work=$(mktemp -d)
trap 'rm -rf "$prefix" "$work"' EXIT
cmake --install build/release --prefix "$prefix" > "$work/install.log"
cmake -S examples/cpp -B "$work/example" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" > "$work/configure.log"
cmake --build "$work/example" > "$work/build.log"
OMP_NUM_THREADS=1 "$work/example/rbc_forces"
pydir=$(find "$prefix" -type d -name dist-packages | head -n 1)
(cd "$work" && PYTHONPATH="$pydir" OMP_NUM_THREADS=1 /usr/bin/python3 -c "import bendlab, sys; assert bendlab.__file__.startswith('$prefix'), bendlab.__file__")
(cd "$work" && PYTHONPATH="$pydir" OMP_NUM_THREADS=1 /usr/bin/python3 "$OLDPWD/examples/python/figure8.py" --triangles 1280 --out "$work/figure8.png")
test -s "$work/figure8.png"
"$prefix/bin/bendlab" --version
echo "check_install: the installed library, CLI and Python module work from $prefix"
