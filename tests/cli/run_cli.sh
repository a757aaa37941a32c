#!/usr/bin/env bash
# Tests of the command-line program build/vsgl: argument errors, bad bundles,
# unwritable outputs, info, dry runs, renders read back with OpenImageIO,
# progress on a terminal and not, cancellation. Scenes come from
# tests/cli/make_scene.py, an independent writer of docs/bundle-format.md.
#
# Usage: tests/cli/run_cli.sh [name-substring]   (from anywhere)
# Ends with "N passed, N failed"; exit status non-zero on any failure.
set -uo pipefail
cd "$(dirname "$0")/../.."
ROOT=$PWD
VSGL=${VSGL:-$ROOT/build/vsgl}
PY=${PYTHON:-/usr/bin/python3}
[ -x "$PY" ] || PY=python3
FILTER=${1:-}
pass=0; fail=0
T=$(mktemp -d /tmp/vsgl_cli_XXXXXX)
trap 'rm -rf "$T"' EXIT

if [ ! -x "$VSGL" ]; then
  make --no-print-directory build/vsgl >/dev/null 2>&1 || true
fi
if [ ! -x "$VSGL" ]; then
  echo "run_cli.sh: $VSGL is missing and 'make build/vsgl' failed"
  echo "0 passed, 1 failed"; exit 1
fi
have() { command -v "$1" >/dev/null 2>&1; }
# OpenImageIO's oiiotool reads the EXRs back (the independent reader): required.
if ! have oiiotool; then
  echo "run_cli.sh: oiiotool is missing: install openimageio-tools (tools/deps.sh test)"
  echo "0 passed, 1 failed"; exit 1
fi

ok()  { pass=$((pass + 1)); printf 'PASS %s\n' "$1"; }
bad() { fail=$((fail + 1)); printf 'FAIL %s\n' "$1"; shift; printf '    %s\n' "$@"; }
want() { [ -z "$FILTER" ] || [[ "$1" == *"$FILTER"* ]]; }

# run: execute the command, keep rc, stdout, stderr.
run() { "$@" >"$T/out" 2>"$T/err"; rc=$?; }

# expect_fail NAME RC SUBSTRING CMD...: exit status RC and exactly one stderr
# line "vsgl: ...SUBSTRING...".
expect_fail() {
  local name=$1 code=$2 sub=$3; shift 3
  want "$name" || return 0
  run "$@"
  local lines; lines=$(wc -l <"$T/err")
  local line; line=$(head -1 "$T/err")
  if [ "$rc" -eq "$code" ] && [ "$lines" -eq 1 ] && [[ "$line" == "vsgl: "* ]] && [[ "$line" == *"$sub"* ]]; then
    ok "$name"
  else
    bad "$name" "command: $*" "want exit $code and one line 'vsgl: ...$sub...'" \
        "got exit $rc, $lines stderr lines: $(head -3 "$T/err" | tr '\n' '|')"
  fi
}

# expect_ok NAME CMD...: exit status 0.
expect_ok() {
  local name=$1; shift
  run "$@"
  if [ "$rc" -eq 0 ]; then return 0; fi
  bad "$name" "command: $*" "exit $rc: $(head -3 "$T/err" | tr '\n' '|')"
  return 1
}

SCENE=$T/scene.vsglb
"$PY" tests/cli/make_scene.py "$SCENE" --width 64 --height 48 --output "$T/from_bundle.exr" --frame 7
"$PY" tests/cli/make_scene.py "$T/nooutput.vsglb" --no-settings

# ---- help and version -------------------------------------------------------
if want help; then
  if expect_ok help "$VSGL" --help && grep -q "usage: vsgl render SCENE.vsglb" "$T/out" && grep -q -- "--visibility" "$T/out"; then
    ok help; else [ "$rc" -ne 0 ] || bad help "usage text missing: $(head -2 "$T/out")"; fi
fi
if want version; then
  v=$("$VSGL" --version); rc=$?
  # the bundle format the header declares
  bmaj=$(awk '/#define VSGL_BUNDLE_VERSION_MAJOR/ {print $3}' csrc/include/vsgl/io.h)
  bmin=$(awk '/#define VSGL_BUNDLE_VERSION_MINOR/ {print $3}' csrc/include/vsgl/io.h)
  if [ $rc -eq 0 ] && [[ "$v" =~ ^vsgl\ [0-9]+\.[0-9]+\.[0-9]+ ]] && [[ "$v" == *"bundle format $bmaj.$bmin"* ]]; then ok version
  else bad version "got exit $rc: $v"; fi
fi

# ---- bad command lines: exit 2, one line -------------------------------------
expect_fail args_none          2 "no command given"              "$VSGL"
expect_fail args_unknown_cmd   2 "unknown command 'frobnicate'"  "$VSGL" frobnicate
expect_fail args_unknown_opt   2 "unknown option '--bogus'"      "$VSGL" render "$SCENE" --bogus
expect_fail args_missing_value 2 "option --aa needs a value"     "$VSGL" render "$SCENE" --aa
expect_fail args_negative      2 "'-3' is not a whole number"    "$VSGL" render "$SCENE" --aa -3
expect_fail args_junk_number   2 "'2x' is not a whole number"    "$VSGL" render "$SCENE" --rsm 2x
expect_fail args_zero_vsgls    2 "'0' is not a whole number >= 1" "$VSGL" render "$SCENE" --vsgls 0
expect_fail args_huge_number   2 "is not a whole number"         "$VSGL" render "$SCENE" --seed 99999999999
expect_fail args_bad_enum      2 "'foo' is not one of two|fis|kmeans" "$VSGL" render "$SCENE" --fit=foo
expect_fail args_bad_preset    2 "is not one of preview|balanced|quality|auto" "$VSGL" render "$SCENE" --preset fast
expect_fail args_flag_value    2 "option --half takes no value"  "$VSGL" render "$SCENE" --half=1
expect_fail args_two_scenes    2 "unexpected argument"           "$VSGL" render "$SCENE" other.vsglb
expect_fail args_no_scene      2 "no scene bundle given"         "$VSGL" render -o "$T/x.exr"
expect_fail args_info_output   2 "info takes only"               "$VSGL" info "$SCENE" -o "$T/x.exr"
expect_fail args_empty_output  2 "non-empty path"                "$VSGL" render "$SCENE" -o ""
expect_fail no_output_path     2 "no output path"                "$VSGL" render "$T/nooutput.vsglb"

# ---- bad bundles: exit 1, one line naming the problem ------------------------
for kind in truncate magic version2 nan-position nan-power huge-count crc; do
  "$PY" tests/cli/make_scene.py "$T/bad-$kind.vsglb" --break "$kind"
done
expect_fail bundle_missing   1 "No such file or directory"   "$VSGL" render "$T/none.vsglb" -o "$T/x.exr"
expect_fail bundle_directory 1 "not a regular file"          "$VSGL" info "$T"
expect_fail bundle_truncated 1 "truncated: header says"      "$VSGL" render "$T/bad-truncate.vsglb" -o "$T/x.exr"
expect_fail bundle_magic     1 "wrong magic number"          "$VSGL" info "$T/bad-magic.vsglb"
expect_fail bundle_version   1 "version 2.0, this library reads 1.x" "$VSGL" info "$T/bad-version2.vsglb"
expect_fail bundle_nan_pos   1 "section POS  (positions): vertex 0 component 1 is NaN" "$VSGL" render "$T/bad-nan-position.vsglb" -o "$T/x.exr"
expect_fail bundle_nan_power 1 "section LGHT (lights): light 0 field power is NaN" "$VSGL" info "$T/bad-nan-power.vsglb"
expect_fail bundle_huge      1 "exceed the file"             "$VSGL" info "$T/bad-huge-count.vsglb"
expect_fail bundle_crc       1 "CRC32 mismatch"              "$VSGL" info "$T/bad-crc.vsglb"
if want bundle_no_output_file; then
  if [ -e "$T/x.exr" ]; then bad bundle_no_output_file "a failed run created $T/x.exr"; else ok bundle_no_output_file; fi
fi

# ---- unwritable outputs: exit 1 before rendering, nothing created -------------
mkdir -p "$T/adir"; : >"$T/afile"
expect_fail out_missing_dir 1 "No such file or directory" "$VSGL" render "$SCENE" -o "$T/missing/x.exr"
expect_fail out_is_dir      1 "is a directory"            "$VSGL" render "$SCENE" -o "$T/adir"
expect_fail out_under_file  1 "not a directory"           "$VSGL" render "$SCENE" -o "$T/afile/x.exr"
if want out_unwritable_dir && [ "$(id -u)" = 0 ] && have setpriv; then
  # As root the check needs an unprivileged user (65534). It may not be able
  # to reach the checkout (a clone inside a 0700 directory such as mktemp -d
  # makes): it runs copies of vsgl and libvsgl.so ($ORIGIN rpath) from $T.
  mkdir -p "$T/ro" "$T/bin"; chmod 0555 "$T/ro"; chmod 0755 "$T" "$T/bin"
  cp "$VSGL" "$(dirname "$VSGL")/libvsgl.so" "$T/bin/" 2>/dev/null
  chmod a+rX "$T/bin"/* "$SCENE" 2>/dev/null
  as_nobody() { setpriv --reuid=65534 --regid=65534 --clear-groups "$@"; }
  if ! why=$(as_nobody "$T/bin/vsgl" info "$SCENE" 2>&1 >/dev/null); then
    printf 'SKIP out_unwritable_dir: uid 65534 cannot run vsgl from %s: %s\n' "$T/bin" "$(head -1 <<<"$why")"
  else
    run as_nobody "$T/bin/vsgl" render "$SCENE" -o "$T/ro/x.exr"
    if [ "$rc" -eq 1 ] && [ "$(wc -l <"$T/err")" -eq 1 ] && grep -q "^vsgl: .*Permission denied" "$T/err" && [ -z "$(ls -A "$T/ro")" ]; then
      ok out_unwritable_dir; else bad out_unwritable_dir "exit $rc: $(cat "$T/err")"; fi
  fi
elif want out_unwritable_dir && [ "$(id -u)" != 0 ]; then
  mkdir -p "$T/ro"; chmod 0555 "$T/ro"
  expect_fail out_unwritable_dir 1 "Permission denied" "$VSGL" render "$SCENE" -o "$T/ro/x.exr"
fi

# ---- info ---------------------------------------------------------------------
if want info; then
  if expect_ok info "$VSGL" info "$SCENE"; then
    miss=""
    for l in "vertices: 20" "triangles: 10" "materials: 3" "lights: 1" "bounds: (-2, -2, 0) .. (2, 2, 4) m" \
             "camera: perspective 64x48, lens 35 mm" "light 0: spot, power 500 W" "output: $T/from_bundle.exr" \
             "frame: 7" "seed=3" "valid: yes (10 triangles kept"; do
      grep -qF "$l" "$T/out" || miss="$miss [$l]"
    done
    if [ -z "$miss" ]; then ok info; else bad info "missing lines:$miss" "$(cat "$T/out")"; fi
  fi
fi

# ---- dry run --------------------------------------------------------------------
if want dry_run; then
  if expect_ok dry_run "$VSGL" render "$SCENE" -o "$T/dry.exr" --dry-run --preset quality; then
    if grep -q "dry run: .* would render 64x48 to $T/dry.exr with method=vsgl aa=3 rsm=512 fit=lattice" "$T/out" && [ ! -e "$T/dry.exr" ]; then
      ok dry_run; else bad dry_run "$(cat "$T/out")" "file exists: $([ -e "$T/dry.exr" ] && echo yes || echo no)"; fi
  fi
fi

# Issue 10: the dry run validates the settings as the render does (it used
# to call all of these valid), and a huge image is refused up front with a
# message naming the size, the estimate and the limit (a 16384^2 render grew
# to 23 GB and was killed after 8.5 minutes without a message).
expect_fail dry_run_aa17      1 "settings: aa_samples is 17 (valid 1..16)"          "$VSGL" render "$SCENE" -o "$T/dry.exr" --dry-run --aa 17
expect_fail dry_run_rsm1      1 "settings: rsm_resolution is 1 (valid 2..8192)"     "$VSGL" render "$SCENE" -o "$T/dry.exr" --dry-run --rsm 1
expect_fail dry_run_rsm16384  1 "settings: rsm_resolution is 16384 (valid 2..8192)" "$VSGL" render "$SCENE" -o "$T/dry.exr" --dry-run --rsm 16384
expect_fail dry_run_vsgls     1 "settings: vsgl_count is 65537 (valid 1..65536)"    "$VSGL" render "$SCENE" -o "$T/dry.exr" --dry-run --vsgls 65537
if want huge || want dry_run || want memory; then
  "$PY" tests/cli/make_scene.py "$T/huge.vsglb" --width 16384 --height 16384
fi
# balanced takes 1 sample per pixel from 320 x 240 up (aa_pixel_limit), and the estimate says so;
# --aa-pixel-limit 0 keeps its 2 x 2
expect_fail dry_run_huge 1 "render: 16384x16384 with aa 1 and RSM 256 needs about 83.3 GiB" "$VSGL" render "$T/huge.vsglb" -o "$T/huge.exr" --dry-run --preset balanced --max-memory 20G
expect_fail dry_run_huge_aa2 1 "render: 16384x16384 with aa 2 and RSM 256 needs about 99.3 GiB" "$VSGL" render "$T/huge.vsglb" -o "$T/huge.exr" --dry-run --preset balanced --aa-pixel-limit 0 --max-memory 20G
if want render_huge_refused; then
  start=$(date +%s)
  expect_fail render_huge_refused 1 "more than the memory limit of 20.0 GiB (max_memory)" "$VSGL" render "$T/huge.vsglb" -o "$T/huge.exr" --preset balanced --max-memory 20G
  [ $(( $(date +%s) - start )) -le 10 ] || bad render_huge_refused_fast "took $(( $(date +%s) - start )) s to refuse"
  [ ! -e "$T/huge.exr" ] || bad render_huge_refused_file "a refused render wrote $T/huge.exr"
fi
expect_fail render_huge_machine 1 "(memory available on this machine)" "$VSGL" render "$T/huge.vsglb" -o "$T/huge.exr" --preset quality --aa 16 --aa-pixel-limit 0
# Found by tests/fuzz/fuzz_cli.c: a newline inside a quoted argument split the one error line.
expect_fail args_newline       2 "unknown option '--bo?gus'"   "$VSGL" render "$SCENE" $'--bo\ngus'
expect_fail args_max_memory 2 "option --max-memory: '12Q' is not a size" "$VSGL" render "$SCENE" --max-memory 12Q
if want dry_run_memory; then
  if expect_ok dry_run_memory "$VSGL" render "$SCENE" -o "$T/dry.exr" --dry-run -v; then
    if grep -Eq "; memory about [0-9.]+ MiB \(limit [0-9.]+ [GM]iB\)$" "$T/out" && grep -q "^vsgl: memory: about .*(output planes .*G-buffer .*RSMs .*); limit " "$T/err"; then
      ok dry_run_memory; else bad dry_run_memory "stdout: $(cat "$T/out")" "stderr: $(tr '\n' '|' <"$T/err")"; fi
  fi
fi

# The estimate against the peak RSS of real renders (1024^2, 2048^2).
if want memory_estimate; then
  for n in 1024 2048; do
    "$PY" tests/cli/make_scene.py "$T/m$n.vsglb" --width $n --height $n
    for preset in preview balanced; do
      est=$("$VSGL" render "$T/m$n.vsglb" -o "$T/m.exr" --preset $preset --dry-run -v 2>&1 | grep '^vsgl: memory: about' |
            sed -E 's/^vsgl: memory: about ([0-9.]+) (GiB|MiB).*/\1 \2/' | awk '{print ($2 == "GiB" ? $1 * 1024 : $1)}')
      rss=$("$PY" -c 'import resource, subprocess, sys
subprocess.run(sys.argv[1:], check=True, stderr=subprocess.DEVNULL)
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0)' "$VSGL" render "$T/m$n.vsglb" -o "$T/m.exr" --preset $preset)
      # within -10 % .. +10 % of the peak, allowing 64 MiB for the program, its libraries and the scene
      if [ -n "$est" ] && [ -n "$rss" ] && awk -v e="$est" -v r="$rss" 'BEGIN { exit !(e >= 0.9 * (r - 64) && e <= 1.1 * r + 8) }'; then
        ok "memory_estimate ${n}^2 $preset (estimate $est MiB, peak RSS $rss MiB)"
      else
        bad "memory_estimate ${n}^2 $preset" "estimate '$est' MiB, peak RSS '$rss' MiB"
      fi
    done
  done
fi

# A scene without lights renders black and says so (it used to exit 0 silently).
if want render_no_lights; then
  "$PY" tests/cli/make_scene.py "$T/dark.vsglb" --no-lights
  if expect_ok render_no_lights "$VSGL" render "$T/dark.vsglb" -o "$T/dark.exr"; then
    if grep -q "^vsgl: warning: .*no lights.*black" "$T/err"; then ok render_no_lights
    else bad render_no_lights "stderr: $(tr '\n' '|' <"$T/err")"; fi
  fi
fi

# ---- renders ----------------------------------------------------------------------
PASSES="DiffInd GlossInd DiffCol GlossCol Diff Gloss Combined"
if want render_float && expect_ok render_float "$VSGL" render "$SCENE" -o "$T/out.exr" --preset preview --float \
    --passes all; then
  errs=""
  [ -s "$T/out.exr" ] || errs="$errs [no file]"
  grep -q $'\r' "$T/err" && errs="$errs [carriage return on a non-terminal]"
  grep -Eq '^vsgl: (gbuffer|rsm|fit|shade) \([0-9]+%\)$' "$T/err" || errs="$errs [no plain progress lines: $(head -2 "$T/err" | tr '\n' '|')]"
  info=$(oiiotool --info -v "$T/out.exr" 2>&1)
  grep -q "64 x   48, 22 channel, float openexr" <<<"$info" || errs="$errs [header: $(head -2 <<<"$info" | tr '\n' '|')]"
  for p in $PASSES; do
    grep -q "VSGL\.$p\.R" <<<"$info" || errs="$errs [no VSGL.$p.R]"
  done
  grep -q "VSGL.Combined.A" <<<"$info" || errs="$errs [no VSGL.Combined.A]"
  grep -q 'vsgl.settings: "method=vsgl aa=1 rsm=128 fit=lattice vsgls=32' <<<"$info" || errs="$errs [settings metadata]"
  stats=$(oiiotool --stats "$T/out.exr" 2>&1)
  nan=$(grep "NanCount" <<<"$stats" | tr -s ' ' '\n' | grep -Ec '^[1-9]')
  inf=$(grep "InfCount" <<<"$stats" | tr -s ' ' '\n' | grep -Ec '^[1-9]')
  [ "$nan" -eq 0 ] && [ "$inf" -eq 0 ] || errs="$errs [non-finite: $nan NaN, $inf Inf channels]"
  # Some indirect light reaches the floor: the maximum of DiffInd is positive.
  mx=$(grep "Stats Max" <<<"$stats" | awk '{print $8}')   # 4th channel listed = DiffInd.R after Combined RGBA
  awk -v m="$mx" 'BEGIN { exit !(m > 0) }' || errs="$errs [DiffInd.R max $mx not > 0]"
  if [ -z "$errs" ]; then ok render_float; else bad render_float "$errs"; fi
fi

if want render_half_verbose && expect_ok render_half_verbose "$VSGL" render "$SCENE" --half -v --preset preview; then
  errs=""
  [ -s "$T/from_bundle.exr" ] || errs="$errs [bundle's output path not used]"
  for l in "vsgl: settings: method=vsgl" "vsgl: render " "gbuffer " "rsm " "fit " "shade " "vsgl: lights used 1, skipped 0" "(64x48, half, zip)"; do
    grep -qF "$l" "$T/err" || errs="$errs [stderr lacks '$l']"
  done
  # the default passes: what the add-on's compositor setup reads (no DiffCol, GlossCol)
  oiiotool --info "$T/from_bundle.exr" 2>&1 | grep -q "16 channel, half openexr" || errs="$errs [not 16 half channels: $(oiiotool --info "$T/from_bundle.exr" 2>&1)]"
  oiiotool --info -v "$T/from_bundle.exr" 2>&1 | grep -q "VSGL.DiffCol" && errs="$errs [DiffCol written by default]"
  if [ -z "$errs" ]; then ok render_half_verbose; else bad render_half_verbose "$errs"; fi
fi

# The auto preset says what it chose and why under -v (the 64x48 scene: below
# 320x240, so aa stays 2; its one light's RSM from its footprint), and
# --aa is a ceiling it keeps.
if want render_auto && expect_ok render_auto "$VSGL" render "$SCENE" -o "$T/auto.exr" --preset auto --aa 3 -v; then
  errs=""
  for l in "vsgl: budget: auto: aa 3: 64x48, < 76800 pixels" "vsgl: budget: auto: glossy" \
           "vsgl: budget: light 0: 100 % of the light on what the camera sees: 192 VSGLs, RSM " \
           "vsgl: budget: RSM sides by footprint (85 texels per VSGL on it): "; do
    grep -qF "$l" "$T/err" || errs="$errs [stderr lacks '$l']"
  done
  if [ -z "$errs" ]; then ok render_auto; else bad render_auto "$errs" "$(grep budget "$T/err" | tr '\n' '|')"; fi
fi

# Compression choices, read back by oiiotool; -v names the compression
# (it indexed a 4-name table and crashed on rle).
if want render_compression; then
  for c in none zips zip piz rle pxr24 b44 b44a; do
    if expect_ok render_compression "$VSGL" render "$SCENE" -o "$T/c-$c.exr" --compression "$c" --preset preview -v; then
      if ! oiiotool --info -v "$T/c-$c.exr" 2>&1 | grep -q "compression: \"$c\""; then
        bad "render_compression $c" "$(oiiotool --info -v "$T/c-$c.exr" 2>&1 | grep -i compression)"
      elif ! grep -q "half, $c)" "$T/err"; then bad "render_compression $c -v" "$(tail -1 "$T/err")"
      else ok "render_compression $c"; fi
    fi
  done
fi
# The add-on's enum names (PULLED_OUT, BRUTE_FORCE) in lower case, and the
# short spellings of earlier releases.
for spelling in "--diffuse pulled-out --method brute-force" "--diffuse pulled --method brute"; do
  # shellcheck disable=SC2086
  if expect_ok "args_names $spelling" "$VSGL" render "$SCENE" -o "$T/names.exr" $spelling --dry-run; then
    if grep -q "method=brute-force" "$T/out" && grep -q "diffuse=pulled-out" "$T/out"; then ok "args_names $spelling"
    else bad "args_names $spelling" "$(head -3 "$T/out" | tr '\n' '|')"; fi
  fi
done
# --glossy mrp: the rectangle-proxy glossy mode (docs/mrp.md)
if want args_glossy_mrp && expect_ok "args_glossy_mrp" "$VSGL" render "$SCENE" -o "$T/mrp.exr" --glossy mrp --dry-run; then
  if grep -q "glossy=mrp" "$T/out"; then ok "args_glossy_mrp"
  else bad "args_glossy_mrp" "$(head -3 "$T/out" | tr '\n' '|')"; fi
fi
# --glossy hybrid: MRP per pixel where it applies (docs/mrp.md §4)
if want args_glossy_hybrid && expect_ok "args_glossy_hybrid" "$VSGL" render "$SCENE" -o "$T/hyb.exr" --glossy hybrid \
    --dry-run; then
  if grep -q "glossy=hybrid" "$T/out"; then ok "args_glossy_hybrid"
  else bad "args_glossy_hybrid" "$(head -3 "$T/out" | tr '\n' '|')"; fi
fi
# --mrp-min-area: the MRP modes' proxy size threshold (vsgl_render_settings.mrp_min_area)
if want args_mrp_min_area && expect_ok "args_mrp_min_area" "$VSGL" render "$SCENE" -o "$T/mrpa.exr" --glossy mrp \
    --mrp-min-area 2.5 --dry-run; then
  if grep -q "glossy=mrp.*mrp_min_area=2.5" "$T/out"; then ok "args_mrp_min_area"
  else bad "args_mrp_min_area" "$(head -3 "$T/out" | tr '\n' '|')"; fi
fi
expect_fail args_bad_mrp_min_area 2 "option --mrp-min-area: '-1' is not an area in m^2 >= 0" "$VSGL" render "$SCENE" \
  --mrp-min-area -1
expect_fail args_bad_mrp_min_area_nan 2 "option --mrp-min-area: 'nan' is not an area in m^2 >= 0" "$VSGL" render "$SCENE" \
  --mrp-min-area nan
# --glossy-lobes: GGX's lobes in the half-vector glossy model (vsgl_render_settings.glossy_lobes)
if want args_glossy_lobes && expect_ok "args_glossy_lobes" "$VSGL" render "$SCENE" -o "$T/lobes.exr" --glossy asg2 \
    --glossy-lobes 5 --dry-run; then
  if grep -q "glossy=asg2.*glossy_lobes=5" "$T/out"; then ok "args_glossy_lobes"
  else bad "args_glossy_lobes" "$(head -3 "$T/out" | tr '\n' '|')"; fi
fi
expect_fail args_bad_glossy_lobes 1 "settings: glossy_lobes is 3 (valid 4 or 5; 0 = 4)" "$VSGL" render "$SCENE" \
  --glossy-lobes 3 --dry-run
expect_fail args_bad_compression 2 "'lzma' is not one of zip|zips|piz|none|rle|pxr24|b44|b44a" "$VSGL" render "$SCENE" \
  --compression lzma
# --zip-level: the deflate level of zip / zips (vsgl_exr_options.zip_level): 1..9, lossless; the library refuses 10
if want args_zip_level && expect_ok args_zip_level "$VSGL" render "$SCENE" -o "$T/z1.exr" --zip-level 1 &&
    expect_ok args_zip_level "$VSGL" render "$SCENE" -o "$T/z9.exr" --zip-level 9; then
  s1=$(stat -c %s "$T/z1.exr"); s9=$(stat -c %s "$T/z9.exr")
  if [ "$s9" -lt "$s1" ] && idiff -q -a "$T/z1.exr" "$T/z9.exr" >/dev/null 2>&1; then ok args_zip_level
  else bad args_zip_level "level 9: $s9 bytes, level 1: $s1 bytes, idiff: $(idiff -a "$T/z1.exr" "$T/z9.exr" 2>&1 | tail -1)"; fi
fi
expect_fail args_bad_zip_level 2 "option --zip-level: '10' is not a deflate level 1..9" "$VSGL" render "$SCENE" \
  -o "$T/z10.exr" --zip-level 10
expect_fail args_bad_zip_level_0 2 "option --zip-level: '0' is not a whole number >= 1" "$VSGL" render "$SCENE" \
  -o "$T/z0.exr" --zip-level 0

# --passes: only the passes asked for, by name; a wrong name is refused before rendering
if want args_passes && expect_ok args_passes "$VSGL" render "$SCENE" -o "$T/p2.exr" --passes Gloss,Diff &&
    expect_ok args_passes "$VSGL" render "$SCENE" -o "$T/p1.exr" --passes=Combined; then
  c2=$(oiiotool --info -v "$T/p2.exr" 2>&1 | grep -o "channel list: .*")
  c1=$(oiiotool --info -v "$T/p1.exr" 2>&1 | grep -o "channel list: .*")
  if [ "$c2" = "channel list: VSGL.Diff.R, VSGL.Diff.G, VSGL.Diff.B, VSGL.Gloss.R, VSGL.Gloss.G, VSGL.Gloss.B" ] &&
      [ "$c1" = "channel list: VSGL.Combined.R, VSGL.Combined.G, VSGL.Combined.B, VSGL.Combined.A" ]; then
    ok args_passes
  else bad args_passes "Gloss,Diff: '$c2'; Combined: '$c1'"; fi
fi
expect_fail args_bad_passes 2 "option --passes: 'Foo' is not a pass (DiffInd GlossInd DiffCol GlossCol Diff Gloss Combined" \
  "$VSGL" render "$SCENE" -o "$T/pf.exr" --passes Diff,Foo
expect_fail args_bad_passes_empty 2 "option --passes: '' is not a pass" "$VSGL" render "$SCENE" -o "$T/pe.exr" --passes ""

# --stride-pixels: the image size --shade-stride is meant for (vsgl_render_settings.stride_pixels); every
# preset's 76800 makes balanced's stride 2 a 3 at 480 x 360, and the render says so
if want args_stride_pixels && expect_ok "args_stride_pixels" "$VSGL" render "$SCENE" -o "$T/sp.exr" --preset balanced \
    --stride-pixels 0 --dry-run; then
  if grep -q "stride=2 .*stride_pixels=0" "$T/out"; then ok "args_stride_pixels"
  else bad "args_stride_pixels" "$(head -3 "$T/out" | tr '\n' '|')"; fi
fi
if want render_stride_pixels; then
  "$PY" tests/cli/make_scene.py "$T/sp.vsglb" --width 480 --height 360
  if expect_ok render_stride_pixels "$VSGL" render "$T/sp.vsglb" -o "$T/sp.exr" --preset balanced; then
    if grep -q "skipped: shading: one pixel in 3 x 3 shaded, not 2 x 2: 480 x 360 is 2.2x stride_pixels (76800 pixels)" \
        "$T/err"; then ok "render_stride_pixels"; else bad "render_stride_pixels" "$(tr '\n' '|' < "$T/err" | head -c 600)"; fi
  fi
  if expect_ok render_stride_pixels_off "$VSGL" render "$T/sp.vsglb" -o "$T/sp0.exr" --preset balanced --stride-pixels 0
  then
    if grep -q "shading: one pixel in" "$T/err"; then bad "render_stride_pixels_off" "the stride was scaled"
    else ok "render_stride_pixels_off"; fi
  fi
fi

# What the renderer skipped is printed once, with or without -v.
if want render_skipped; then
  "$PY" tests/cli/make_scene.py "$T/up.vsglb" --light-up
  for v in "" -v; do
    if expect_ok render_skipped "$VSGL" render "$T/up.vsglb" -o "$T/up.exr" $v; then
      n=$(grep -c '^vsgl: skipped: light 1: ' "$T/err")
      if [ "$n" -eq 1 ]; then ok "render_skipped${v:+ (-v)}"; else bad "render_skipped${v:+ (-v)}" "$n 'vsgl: skipped: light 1' lines: $(tr '\n' '|' <"$T/err")"; fi
    fi
  done
fi

# A failed render (settings the library refuses) leaves an existing EXR untouched.
if want render_failure_keeps_file && [ -s "$T/out.exr" ]; then
  before=$(cksum <"$T/out.exr")
  expect_fail render_failure_keeps_file 1 "aa_samples" "$VSGL" render "$SCENE" -o "$T/out.exr" --aa 1000
  [ "$(cksum <"$T/out.exr")" = "$before" ] || bad render_failure_keeps_file_bytes "out.exr changed after a failed render"
  [ -z "$(ls -A "$T" | grep '\.tmp-')" ] || bad render_failure_keeps_file_temp "temporary file left: $(ls -A "$T")"
fi

# Same pixels with 1 and 2 threads (the library promises determinism).
if want render_deterministic; then
  if expect_ok render_deterministic "$VSGL" render "$SCENE" -o "$T/t1.exr" --threads 1 --fit fis --vsgls 16 &&
     expect_ok render_deterministic "$VSGL" render "$SCENE" -o "$T/t2.exr" --threads 2 --fit fis --vsgls 16; then
    h1=$(oiiotool --hash "$T/t1.exr" 2>&1 | grep -o 'SHA-1: [0-9A-F]*'); h2=$(oiiotool --hash "$T/t2.exr" 2>&1 | grep -o 'SHA-1: [0-9A-F]*')
    if [ -n "$h1" ] && [ "$h1" = "$h2" ]; then ok render_deterministic; else bad render_deterministic "pixel hashes differ: $h1 vs $h2"; fi
  fi
fi

# Progress on a terminal: one line updated with \r (script(1) provides the tty).
if want render_tty_progress && have script; then
  script -qfec "$VSGL render '$SCENE' -o '$T/tty.exr' --preset preview" /dev/null >"$T/tty.txt" 2>&1; rc=$?
  if [ $rc -eq 0 ] && grep -q $'\rvsgl: shade' "$T/tty.txt" && ! grep -Eq '^vsgl: (gbuffer|rsm|fit|shade) \(' "$T/tty.txt"; then
    ok render_tty_progress; else bad render_tty_progress "exit $rc: $(tr '\r' '~' <"$T/tty.txt" | head -3)"; fi
fi

# SIGINT cancels: exit 130, one line "vsgl: cancelled", no output file.
if want render_cancel; then
  "$PY" tests/cli/make_scene.py "$T/big.vsglb" --width 1920 --height 1080
  "$VSGL" render "$T/big.vsglb" -o "$T/big.exr" --fit fis --vsgls 1024 --aa 2 2>"$T/err" &
  pid=$!
  sleep 1
  kill -INT $pid
  for _ in $(seq 1 120); do kill -0 $pid 2>/dev/null || break; sleep 0.25; done
  if kill -0 $pid 2>/dev/null; then kill -9 $pid; wait $pid 2>/dev/null; bad render_cancel "still running 30 s after SIGINT"
  else
    wait $pid; rc=$?
    if [ $rc -eq 130 ] && [ "$(tail -1 "$T/err")" = "vsgl: cancelled" ] && [ ! -e "$T/big.exr" ]; then ok render_cancel
    else bad render_cancel "exit $rc, stderr: $(tr '\n' '|' <"$T/err")" "file: $([ -e "$T/big.exr" ] && echo exists || echo none)"; fi
  fi
fi

# Issue 10: SIGINT or SIGTERM during the EXR write (12-15 s at 4K) was
# ignored: the process wrote on, exited 0 and replaced the file. Now: exit
# 130, "vsgl: cancelled", the previous file kept, no temporary file left.
# The signal is sent once the write has started (its progress line is out:
# not the output-path check's short-lived probe) and its temporary file exists.
wait_for_temp() {  # wait_for_temp DIR PID STDERR: 0 once writing into a .*.tmp-* file in DIR
  for _ in $(seq 1 1500); do
    grep -q '^vsgl: write' "$3" 2>/dev/null && ls -A "$1" 2>/dev/null | grep -q '\.tmp-' && return 0
    kill -0 "$2" 2>/dev/null || return 1
    sleep 0.02
  done
  return 1
}
if want write_cancel || want write_kill; then
  "$PY" tests/cli/make_scene.py "$T/w4k.vsglb" --width 3840 --height 2160
fi
for sig in INT TERM; do
  name=write_cancel_$sig
  want "$name" || continue
  mkdir -p "$T/wc"; rm -f "$T/wc/"*; echo "previous" >"$T/wc/f.exr"
  "$VSGL" render "$T/w4k.vsglb" -o "$T/wc/f.exr" --preset preview --compression zip 2>"$T/err" &
  pid=$!
  if ! wait_for_temp "$T/wc" $pid "$T/err"; then
    wait $pid; bad "$name" "the write ended (exit $?) before its temporary file was seen"; continue
  fi
  kill -$sig $pid
  wait $pid; rc=$?
  if [ $rc -eq 130 ] && [ "$(tail -1 "$T/err")" = "vsgl: cancelled" ] && [ "$(cat "$T/wc/f.exr")" = "previous" ] &&
     [ -z "$(ls -A "$T/wc" | grep '\.tmp-')" ]; then ok "$name"
  else bad "$name" "exit $rc, stderr: $(tail -2 "$T/err" | tr '\n' '|')" "file: $(head -c 20 "$T/wc/f.exr" | tr -c '[:print:]' '?'), dir: $(ls -A "$T/wc" | tr '\n' ' ')"; fi
done

# Issue 10: kill -9 during a write left .NAME.tmp-* files (up to 57 MB) that
# no later run removed. The next write into the folder removes those whose
# process is gone and says so.
if want write_kill; then
  mkdir -p "$T/wk"
  "$VSGL" render "$T/w4k.vsglb" -o "$T/wk/f.exr" --preset preview --compression zip 2>"$T/err_kill" &
  pid=$!
  if wait_for_temp "$T/wk" $pid "$T/err_kill"; then
    kill -9 $pid; wait $pid 2>/dev/null
    left=$(ls -A "$T/wk" | grep '\.tmp-')
    if [ -z "$left" ]; then bad write_kill "no temporary file after kill -9"
    elif expect_ok write_kill "$VSGL" render "$SCENE" -o "$T/wk/small.exr" --preset preview; then
      if [ -z "$(ls -A "$T/wk" | grep '\.tmp-')" ] && grep -q "^vsgl: warning: removed $T/wk/$left: a temporary file .* of process $pid, which is gone" "$T/err"; then
        ok write_kill
      else bad write_kill "left: $(ls -A "$T/wk" | tr '\n' ' ')" "stderr: $(tr '\n' '|' <"$T/err")"; fi
    fi
  else
    wait $pid; bad write_kill "the write ended before its temporary file was seen"
  fi
fi

echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
