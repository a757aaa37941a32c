#!/usr/bin/env bash
# Run every test suite that exists and end with one line "N passed, N failed".
# Exit non-zero if any suite failed or reported a failure.
set -uo pipefail
cd "$(dirname "$0")/.."
PYTHON=${PYTHON:-/usr/bin/python3}
export BPY_PYTHON=${BPY_PYTHON:-python3}
total_pass=0; total_fail=0; total_skip=0; status=0
log=$(mktemp -d)

count() {  # count <name> <logfile> <exit code> [skips allowed: 1]: add the suite's counts
  local name=$1 file=$2 rc=$3 allow=${4:-1} p f s
  p=$(grep -Eo '([0-9]+) passed' "$file" | tail -1 | grep -Eo '[0-9]+' || echo 0)
  # pytest's "N skipped" and the shell suites' SKIP lines
  s=$(grep -Eo '([0-9]+) skipped' "$file" | awk '{n += $1} END {print n + 0}')
  s=$((s + $(grep -Ec '^SKIP' "$file" || true)))
  f=$(grep -Eo '([0-9]+) (failed|error|errors)' "$file" | tail -1 | grep -Eo '[0-9]+' || echo 0)
  [ -z "$p" ] && p=0; [ -z "$f" ] && f=0
  if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi   # crashed or collected nothing
  if [ "$allow" = 0 ] && [ "$s" -gt 0 ]; then
    echo "run_tests.sh: $name skipped $s tests, and nothing in it may skip"; f=$((f + 1)); rc=1
  fi
  echo "== $name: $p passed, $f failed, $s skipped (exit $rc)"
  total_pass=$((total_pass + p)); total_fail=$((total_fail + f)); total_skip=$((total_skip + s))
  [ "$rc" -ne 0 ] && status=1
  return 0
}

# The newest bpy (Blender as a module) for the add-on, G-buffer and light
# suites: installed once, here, so that every suite after it runs on it.
echo "== bpy in $BPY_PYTHON"
if ! tools/install_bpy.sh; then
  echo "run_tests.sh: tools/install_bpy.sh could not install bpy into $BPY_PYTHON"
  total_fail=$((total_fail + 1)); status=1
fi

echo "== C unit tests"
build/tests/vsgl_tests 2>&1 | tee "$log/c.txt"; count "C unit tests" "$log/c.txt" "${PIPESTATUS[0]}" 0

if [ -d tests/python ] && ls tests/python/test_*.py >/dev/null 2>&1; then
  echo "== Python binding tests ($PYTHON)"
  "$PYTHON" -m pytest -q -rs -p no:cacheprovider tests/python 2>&1 | tee "$log/py.txt"
  count "Python tests" "$log/py.txt" "${PIPESTATUS[0]}" 0
fi

for runner in tests/tools/run_*.sh tests/cli/run_*.sh tests/blender/run_*.sh; do
  [ -x "$runner" ] || continue
  echo "== $runner"
  "$runner" 2>&1 | tee "$log/bl.txt"; count "$runner" "$log/bl.txt" "${PIPESTATUS[0]}"
done

rm -rf "$log"
echo "($total_skip skipped, each with its reason above: the add-on and Blender suites skip what a Blender version cannot do)"
echo "$total_pass passed, $total_fail failed"
exit $status
