#!/usr/bin/env bash
# cmake --install into a temporary prefix: the programs, the library and header, the CMake
# package, the pkg-config file, the systemd unit and the page are where users expect them; a
# consumer builds against the package both ways and evaluates a table; the Python package imports
# from where Debian's python3 looks; the installed daemon serves its page from the installed files.
# usage: check_install.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 src=$2
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
cmake --install "$build" --prefix "$prefix" > "$prefix/install.log"
fail=0
for f in bin/hystlab bin/hystlabd bin/hystlab-sim include/hystlab/hystlab.h lib/libhystlab.so \
         lib/cmake/hystlab/hystlabConfig.cmake lib/cmake/hystlab/hystlabConfigVersion.cmake lib/pkgconfig/hystlab.pc \
         lib/systemd/system/hystlabd.service share/hystlab/web/index.html share/hystlab/web/vendor/uplot/uPlot.iife.min.js \
         share/doc/hystlab/API.md; do
  if [ -e "$prefix/$f" ]; then echo "ok   $f"; else echo "FAIL $f missing"; fail=1; fi
done
libdir=lib
# The unit names the daemon by the prefix the build was configured with (units need absolute paths).
grep -q "ExecStart=.*/bin/hystlabd" "$prefix/lib/systemd/system/hystlabd.service" && echo "ok   the unit starts hystlabd" || { echo "FAIL unit"; fail=1; }
if nm -D --defined-only "$prefix/$libdir/libhystlab.so" | awk '{print $3}' | grep -v '^hystlab_' | grep -q .; then
  echo "FAIL the library exports more than hystlab_*"; fail=1
else echo "ok   the library exports only hystlab_*"; fi

# A consumer: C, against the installed package only.
mkdir -p "$prefix/consumer"
cat > "$prefix/consumer/main.c" <<'C'
#include <stdio.h>
#include <hystlab/hystlab.h>
int main(int argc, char** argv) {
  hystlab_model* m = NULL;
  if (argc < 2 || hystlab_model_load(argv[1], &m) != HYSTLAB_OK) { fprintf(stderr, "%s\n", hystlab_last_error()); return 1; }
  double f = 0;
  for (double x = 0; x <= 4.0; x += 0.5) { hystlab_model_step(m, x, &f); printf("%.17g\n", f); }
  hystlab_model_free(m);
  return 0;
}
C
cat > "$prefix/consumer/CMakeLists.txt" <<'CM'
cmake_minimum_required(VERSION 3.25)
project(consumer C)
find_package(hystlab 0.1 REQUIRED)
add_executable(consumer main.c)
target_link_libraries(consumer PRIVATE hystlab::hystlab)
CM
cmake -S "$prefix/consumer" -B "$prefix/consumer/build" -DCMAKE_PREFIX_PATH="$prefix" > "$prefix/consumer.log" 2>&1
cmake --build "$prefix/consumer/build" >> "$prefix/consumer.log" 2>&1 || { cat "$prefix/consumer.log"; exit 1; }
PKG_CONFIG_PATH="$prefix/$libdir/pkgconfig" cc "$prefix/consumer/main.c" -o "$prefix/consumer/pc" \
  $(PKG_CONFIG_PATH="$prefix/$libdir/pkgconfig" pkg-config --cflags --libs hystlab)
"$prefix/bin/hystlab" identify --model simplified --range 0,4 --subdivisions 8 -o "$prefix/T.json" > /dev/null
a=$("$prefix/consumer/build/consumer" "$prefix/T.json")
b=$(LD_LIBRARY_PATH="$prefix/$libdir" "$prefix/consumer/pc" "$prefix/T.json")
printf 'displacement_mm\n0\n0.5\n1\n1.5\n2\n2.5\n3\n3.5\n4\n' > "$prefix/X.csv"
c=$("$prefix/bin/hystlab" eval --table "$prefix/T.json" --input "$prefix/X.csv" | tail -n +2 | cut -d, -f2)
if [ "$a" = "$b" ] && [ -n "$a" ] && [ "$(echo "$a" | wc -l)" = 9 ]; then echo "ok   find_package and pkg-config consumers agree"; else echo "FAIL consumers: [$a] [$b]"; fail=1; fi
if python3 -c "import sys; a=[float(v) for v in sys.argv[1].split()]; c=[float(v) for v in sys.argv[2].split()]; sys.exit(a != c)" "$a" "$c"; then
  echo "ok   the installed library matches the installed CLI"; else echo "FAIL library [$a] vs CLI [$c]"; fail=1; fi

# The Python package (when the tree built it), where Debian's python3 finds it: under the default
# prefix /usr/local that is /usr/local/lib/python3.X/dist-packages. Every *.py of the package's
# source folder is installed (other people's modules too), and the installed module evaluates the
# table as the installed library does.
if [ -d "$build/python/hystlab" ] && [ -x /usr/bin/python3 ]; then
  ver=$(/usr/bin/python3 -c 'import sys; print("%d.%d" % sys.version_info[:2])')
  pydir="$prefix/lib/python$ver/dist-packages"
  for f in "$src"/models/python/hystlab/*.py; do
    [ -e "$pydir/hystlab/$(basename "$f")" ] && echo "ok   python: hystlab/$(basename "$f")" || { echo "FAIL python: hystlab/$(basename "$f") not installed"; fail=1; }
  done
  p=$(cd "$prefix" && PYTHONPATH="$pydir" PYTHONDONTWRITEBYTECODE=1 /usr/bin/python3 -c '
import sys, hystlab
assert hystlab.__file__.startswith(sys.argv[2]), hystlab.__file__
m = hystlab.Model(hystlab.Table.load(sys.argv[1]))
print("\n".join(repr(f) for f in m.evaluate([k * 0.5 for k in range(9)])))' "$prefix/T.json" "$pydir") || p="(import failed)"
  if python3 -c "import sys; a=[float(v) for v in sys.argv[1].split()]; p=[float(v) for v in sys.argv[2].split()]; sys.exit(a != p)" "$a" "$p" 2>/dev/null; then
    echo "ok   the installed Python module matches the installed library"; else echo "FAIL python [$p] vs library [$a]"; fail=1; fi
fi

# The installed daemon serves the installed page.
"$prefix/bin/hystlabd" --db "$prefix/d.db" --port 0 > "$prefix/daemon.log" 2>&1 &
pid=$!
for _ in $(seq 100); do grep -q "serving the API" "$prefix/daemon.log" && break; sleep 0.1; done
port=$(sed -n 's|.*serving the API and the page on http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$prefix/daemon.log")
page=$(python3 -c "import urllib.request,sys; print(urllib.request.urlopen('http://127.0.0.1:$port/vendor/uplot/uPlot.iife.min.js').status, urllib.request.urlopen('http://127.0.0.1:$port/').read().decode().count('<title>hystlab</title>'))")
kill -TERM $pid; wait $pid || true
[ "$page" = "200 1" ] && echo "ok   the installed daemon serves the installed page" || { echo "FAIL page: $page"; cat "$prefix/daemon.log"; fail=1; }
exit $fail
