#!/usr/bin/env bash
# Tests of the scripts in tools/ that `make test` and CI depend on, run
# against stand-ins (no network, no real pip).
#
# Usage: tests/tools/run_tools.sh [name-substring]
# Ends with "N passed, N failed"; exit status non-zero on any failure.
set -uo pipefail
cd "$(dirname "$0")/../.."
ROOT=$PWD
FILTER=${1:-}
pass=0; fail=0
T=$(mktemp -d /tmp/vsgl_tools_XXXXXX)
trap 'rm -rf "$T"' EXIT
ok()  { pass=$((pass + 1)); printf 'PASS %s\n' "$1"; }
bad() { fail=$((fail + 1)); printf 'FAIL %s\n' "$1"; shift; printf '    %s\n' "$@"; }
want() { [ -z "$FILTER" ] || [[ "$1" == *"$FILTER"* ]]; }

# A stand-in Python: `-c 'import bpy...'` fails until `-m pip install` ran;
# pip behaves like the real one in that PIP_PYTHON in its environment is its
# --python option (it then fails the way pip 23 does).
make_stub() {
  mkdir -p "$T/bin"
  cat >"$T/bin/stubpy" <<'EOF'
#!/usr/bin/env bash
dir=$(dirname "$0")
if [ "$1" = -c ]; then
  case "$2" in
    *"import bpy"*) [ -e "$dir/installed" ] || exit 1; echo "5.9.9" ;;
    *sys.executable*) echo "$0 (Python 3.11)" ;;
  esac
  exit 0
fi
if [ "$1 $2" = "-m pip" ]; then
  echo "PIP_PYTHON=${PIP_PYTHON-<unset>} args: ${*:3}" >>"$dir/pip.log"
  if [ -n "${PIP_PYTHON+x}" ]; then echo "ERROR: Could not locate Python interpreter $PIP_PYTHON" >&2; exit 1; fi
  : >"$dir/installed"; exit 0
fi
exit 2
EOF
  chmod +x "$T/bin/stubpy"
  rm -f "$T/bin/installed" "$T/bin/pip.log"
}

# Fresh machine: bpy missing. The script must reach pip, with the Python it
# was given, and pip must not see PIP_PYTHON (issue 10: every install failed).
if want install_bpy_fresh; then
  make_stub
  out=$(PIP_PYTHON=python3 BPY_PYTHON="$T/bin/stubpy" tools/install_bpy.sh 2>&1); rc=$?
  log=$(cat "$T/bin/pip.log" 2>/dev/null)
  if [ $rc -eq 0 ] && [ -e "$T/bin/installed" ] && [[ "$log" == "PIP_PYTHON=<unset> args: install "*" bpy numpy pytest OpenImageIO<3.1" ]]; then
    ok install_bpy_fresh
  else
    bad install_bpy_fresh "exit $rc; pip calls: ${log:-none}" "output: $(tr '\n' '|' <<<"$out")"
  fi
fi

# Already installed: pip is not called at all.
if want install_bpy_present; then
  make_stub; : >"$T/bin/installed"
  BPY_PYTHON="$T/bin/stubpy" tools/install_bpy.sh >/dev/null 2>&1; rc=$?
  if [ $rc -eq 0 ] && [ ! -e "$T/bin/pip.log" ]; then ok install_bpy_present
  else bad install_bpy_present "exit $rc, pip called: $(cat "$T/bin/pip.log" 2>/dev/null)"; fi
fi

# BPY_VERSION pins a release (the 4.2 LTS run).
if want install_bpy_pin; then
  make_stub
  BPY_VERSION=4.2.23 BPY_PYTHON="$T/bin/stubpy" tools/install_bpy.sh >/dev/null 2>&1; rc=$?
  if [ $rc -eq 0 ] && grep -q "args: install .* bpy==4.2.23 numpy pytest" "$T/bin/pip.log"; then ok install_bpy_pin
  else bad install_bpy_pin "exit $rc, pip calls: $(cat "$T/bin/pip.log" 2>/dev/null)"; fi
fi

# No script hands PIP_PYTHON to a child any more (pip would take it as --python).
# Allowed: removing it (`unset PIP_PYTHON`, `env -u PIP_PYTHON`) and comments.
if want no_pip_python; then
  hits=$(grep -rn 'PIP_PYTHON' Makefile .ci tools tests/blender tests/cli 2>/dev/null |
    grep -v -e 'unset PIP_PYTHON' -e 'env -u PIP_PYTHON' | grep -Ev '^[^:]+:[0-9]+:\s*#')
  if [ -z "$hits" ]; then ok no_pip_python; else bad no_pip_python "$hits"; fi
fi

# run_quality.sh installs flip-evaluator through tools/pip_install.sh: with
# PIP_PYTHON=python3 exported, plain pip failed and FLIP was skipped (a
# fresh venv, 2026-12-03); pip must not see it, and a failure says pip's error.
if want pip_install; then
  make_stub
  PIP_PYTHON=python3 tools/pip_install.sh "$T/bin/stubpy" "$T/pip_out.log" flip-evaluator 2>"$T/pip_err.log"; rc=$?
  if [ $rc -eq 0 ] && grep -q "PIP_PYTHON=<unset> args: install .*flip-evaluator" "$T/bin/pip.log"; then
    ok pip_install_without_pip_python
  else
    bad pip_install_without_pip_python "exit $rc, pip calls: $(cat "$T/bin/pip.log" 2>/dev/null)"
  fi
  printf '#!/usr/bin/env bash\necho "ERROR: No matching distribution found for flip-evaluator" >&2; exit 1\n' >"$T/bin/failpy"
  chmod +x "$T/bin/failpy"
  tools/pip_install.sh "$T/bin/failpy" "$T/pip_out2.log" flip-evaluator 2>"$T/pip_err2.log"; rc=$?
  if [ $rc -eq 1 ] && grep -q "pip failed: ERROR: No matching distribution" "$T/pip_err2.log"; then
    ok pip_install_says_pips_error
  else
    bad pip_install_says_pips_error "exit $rc, stderr: $(cat "$T/pip_err2.log")"
  fi
fi

# Issue 10: the add-on zip carried libvsgl.so but not libembree3,
# libOpenEXRCore or libtbb. Now they are inside, and the loader takes them
# from there (not from the system) through libvsgl's $ORIGIN rpath.
if want addon_zip; then
  if tools/build_addon.sh >"$T/zip.log" 2>&1 && mkdir -p "$T/zip" && (cd "$T/zip" && python3 -c 'import sys, zipfile; zipfile.ZipFile(sys.argv[1]).extractall()' "$ROOT/build/vsgl_indirect.zip"); then
    lib="$T/zip/vsgl_indirect/lib"
    errs=""
    deps=$(ldd "$lib/libvsgl.so")
    for so in libembree3.so.3 libOpenEXRCore-3_1.so.30 libtbb.so.12 libdeflate.so.0; do
      grep -q "^\s*$so => $lib/$so " <<<"$deps" || errs="$errs [$so not taken from the zip: $(grep "$so" <<<"$deps" | xargs)]"
    done
    nf=$(grep -c "not found" <<<"$deps")
    [ "$nf" -eq 0 ] || errs="$errs [$nf libraries not found]"
    out=$(env -u VSGL_LIBRARY -u LD_LIBRARY_PATH /usr/bin/python3 -c '
import sys; sys.path.insert(0, sys.argv[1])
import libvsgl
print(libvsgl.version_string())
print("".join(l for l in open("/proc/self/maps") if "libembree3" in l or "libtbb" in l))' "$T/zip/vsgl_indirect" 2>&1)
    grep -q "^[0-9]*\.[0-9]*\.[0-9]*$" <<<"$out" || errs="$errs [binding cannot load the zip's library: $(head -3 <<<"$out" | tr '\n' '|')]"
    grep -E "libembree3|libtbb" <<<"$out" | grep -vq "$lib/" && errs="$errs [a system copy was mapped: $(grep -E 'libembree3|libtbb' <<<"$out" | grep -v "$lib/" | head -1)]"
    if [ -z "$errs" ]; then ok addon_zip_self_contained; else bad addon_zip_self_contained "$errs"; fi
  else
    bad addon_zip_self_contained "tools/build_addon.sh failed: $(tail -3 "$T/zip.log")"
  fi
fi

# make bench's C programs build against the library's current internals
# (bench_shade did not from 760acca to 2026-12-03, unnoticed: nothing ran it)
if want bench_builds; then
  if [ ! -f build/obj/csrc/src/shade/shade.o ]; then
    bad bench_programs_build "the library's objects are missing: run make first"
  elif BENCH_BUILD_ONLY=1 BENCH_DIR="$T/bench" tools/bench.sh >"$T/bench.log" 2>&1 &&
       [ -x "$T/bench/bench_shade" ] && [ -x "$T/bench/bench_kernel" ]; then
    ok bench_programs_build
  else
    bad bench_programs_build "tools/bench.sh (BENCH_BUILD_ONLY=1) failed: $(grep -m3 -E 'error|Error' "$T/bench.log" | tr '\n' '|')"
  fi
fi

# tools/camera_dense_excess.py (make bench's camera flicker at one sample per
# pixel) runs end to end at a tiny size: the same library twice gives the
# same figures (renders are deterministic), --map writes PNGs, and the
# per-library frames are removed
if want camera_dense_excess; then
  py=${BPY_PYTHON:-python3}
  if ! "$py" -c 'import numpy' >/dev/null 2>&1; then
    bad camera_dense_excess "$py lacks numpy"
  else
    out=$("$py" tools/camera_dense_excess.py --scenes spot_metal_floor --size 40x30 --config preview \
          --libs build/libvsgl.so,build/libvsgl.so --cache "$T/dense" --map "$T/map" 2>&1); rc=$?
    line=$(grep "^spot_metal_floor " <<<"$out")
    cells=$(sed -E 's/^spot_metal_floor +//' <<<"$line")
    first=${cells%%  ->  *}; second=${cells##*  ->  }
    png=$(head -c 8 "$T/map/spot_metal_floor_Gloss.png" 2>/dev/null | od -An -tx1 | tr -d ' \n')
    if [ $rc -eq 0 ] && [[ "$first" =~ ^[0-9]+\.[0-9]{4}\ /\ [0-9]+\.[0-9]{4}$ ]] && [ "$first" = "$second" ] &&
       [ "$png" = 89504e470d0a1a0a ] && ! ls "$T/dense"/run_* >/dev/null 2>&1; then
      ok camera_dense_excess
    else
      bad camera_dense_excess "exit $rc; cells '$first' / '$second'; PNG header '$png'; runs left: $(ls "$T/dense" 2>/dev/null | tr '\n' ' ')" \
          "output: $(tail -5 <<<"$out" | tr '\n' '|')"
    fi
  fi
fi

echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
