#!/usr/bin/env bash
# A test of the test (issue 33): scripts/check-modules must fail on a copy of lib/ with one
# forbidden arrow added, each of the three kinds in turn, and name the file, the line and the arrow.
set -euo pipefail
src="${1:?usage: forbidden_include.sh SOURCE_DIR}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

expect_failure() {  # $1: what it is, $2: file to append to (relative to lib/), $3: the line, $4: text the report must hold
  rm -rf "$tmp/tree"
  mkdir -p "$tmp/tree/docs" "$tmp/tree/scripts"
  cp -r "$src/lib" "$tmp/tree/lib"
  cp "$src/docs/architecture.md" "$tmp/tree/docs/"
  cp "$src/scripts/check-modules" "$tmp/tree/scripts/"
  local file="$tmp/tree/lib/$2"
  mkdir -p "$(dirname "$file")"
  echo "$3" >>"$file"
  local lines
  lines=$(wc -l <"$file")
  set +e
  out=$(python3 "$tmp/tree/scripts/check-modules" --root "$tmp/tree" 2>&1)
  rc=$?
  set -e
  if [ "$rc" -ne 1 ]; then
    echo "FAIL ($1): check-modules returned $rc, not 1:"; echo "$out"; exit 1
  fi
  if ! grep -qF "lib/$2:$lines: $4" <<<"$out"; then
    echo "FAIL ($1): the report does not name lib/$2:$lines and '$4':"; echo "$out"; exit 1
  fi
  echo "ok ($1): $(grep -F "lib/$2:$lines" <<<"$out")"
}

# The tree as it is passes (the other test runs it too; here it shows the copy is faithful).
mkdir -p "$tmp/clean/docs" "$tmp/clean/scripts"
cp -r "$src/lib" "$tmp/clean/lib"
cp "$src/docs/architecture.md" "$tmp/clean/docs/"
cp "$src/scripts/check-modules" "$tmp/clean/scripts/"
python3 "$tmp/clean/scripts/check-modules" --root "$tmp/clean" >/dev/null

expect_failure "an arrow that climbs up" core/src/core.cpp '#include "scenewatch/pipeline/working_memory.h"' "core -> pipeline"
expect_failure "a sideways arrow" segmentation/src/tabletop.cpp '#include "scenewatch/background/occupancy_map.h"' "segmentation -> background"
expect_failure "protobuf outside service" io/src/sequence.cpp '#include "scenewatch.pb.h"' "protobuf"
expect_failure "OpenCV in a public header" background/include/scenewatch/background/appearance.h '#include <opencv2/core.hpp>' "a public header of background"
