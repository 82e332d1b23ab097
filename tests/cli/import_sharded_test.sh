#!/usr/bin/env bash
# scripts/import-sharded as a user meets it: 3 shards over GNU parallel merge into a pack equal,
# file for file and byte for byte, to the one-shot import; a failing shard gives one line naming
# it, a non-zero exit, and leaves an existing WORLD untouched. Exit 77 (skip) without parallel.
#   import_sharded_test.sh SDFSTREAM SOURCE_DIR
set -euo pipefail

tool=$1
script=$2/scripts/import-sharded

if ! command -v parallel >/dev/null 2>&1 ||
   ! env -u PARALLEL parallel --version 2>/dev/null | grep -q '^GNU parallel'; then
  echo "SKIP: GNU parallel is not installed (apt-get install parallel)"
  exit 77
fi

tmp=$(mktemp -d "${TMPDIR:-/tmp}/import-sharded-test.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

failures=0
check() {  # check DESCRIPTION COMMAND...: runs the command, reports FAIL when it fails
  local what=$1
  shift
  if ! "$@"; then
    echo "FAIL: $what"
    failures=$((failures + 1))
  fi
}
# Only these names under DIR (one per line, sorted), so nothing is left behind.
only() { [ "$(ls -A "$1")" = "$2" ]; }

# A 2 m x 1 m x 1 m box: 45 tiles with 32-voxel tiles and 2 LODs (about 0.5 s to import).
cat >box.obj <<'EOF'
v 0 0 0
v 2 0 0
v 2 1 0
v 0 1 0
v 0 0 1
v 2 0 1
v 2 1 1
v 0 1 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
EOF
import_args=(--lods 2 --tile-voxels 32)

"$tool" import box.obj -o one "${import_args[@]}" >/dev/null 2>&1

# 3 shards, 2 at a time, merged.
mkdir out
rc=0
"$script" box.obj -o out/world --shards 3 --jobs 2 --tool "$tool" -- "${import_args[@]}" \
  >sharded.out 2>sharded.err || rc=$?
cat sharded.out sharded.err
check "import-sharded exits 0 (got $rc)" [ "$rc" -eq 0 ]
for i in 0 1 2; do
  check "one line for finished shard $i/3" [ "$(grep -c "^import-sharded: shard $i/3 done " sharded.out)" -eq 1 ]
done
check "no error output" [ ! -s sharded.err ]
check "the same files as the one-shot pack" \
  [ "$(cd one && find . -type f | sort)" = "$(cd out/world 2>/dev/null && find . -type f | sort)" ]
files=0
while IFS= read -r f; do
  files=$((files + 1))
  check "$f equals the one-shot pack's" cmp -s "one/$f" "out/world/$f"
done < <(cd one && find . -type f | sort)
check "the one-shot pack has a manifest and tiles (got $files files)" [ "$files" -gt 3 ]
check "diff -r one-shot merged" diff -r one out/world
check "only WORLD left next to it (shards removed)" only out world

# A failing shard (a scene that does not exist) over an existing WORLD.
mkdir keep
cp -a one keep/world
rc=0
"$script" "$tmp/missing.obj" -o keep/world --shards 3 --jobs 2 --tool "$tool" -- "${import_args[@]}" \
  >failed.out 2>failed.err || rc=$?
cat failed.out failed.err
check "a failing shard exits non-zero" [ "$rc" -ne 0 ]
check "a failing shard gives one line on stderr" [ "$(wc -l <failed.err)" -eq 1 ]
check "the error names the shard and the scene" \
  grep -Eq '^import-sharded: error: shard [0-2]/3 failed.*missing\.obj' failed.err
check "an existing WORLD is untouched" diff -r one keep/world
check "nothing left beside WORLD" only keep world

if [ "$failures" -ne 0 ]; then
  echo "$failures check(s) failed"
  exit 1
fi
echo "ok: merged 3 shards equal the one-shot import ($files files); a failing shard is one line"
