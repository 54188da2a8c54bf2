#!/usr/bin/env bash
# The install tests (issue 35), on the build tree as it is: nothing is built again here.
#
#   tests/install/run.sh prefix BUILD_DIR   (CTest: install.prefix)
#     `cmake --install` into a temporary prefix; from there, with the source and build trees hidden
#     (a private mount namespace, when the kernel allows one): the programs' --version, a simulator
#     scenario rendered and replayed, the daemon finding its installed config; a consumer project
#     (tests/install/consumer) built with find_package(scenewatch) against the prefix and run; the
#     Python client pip-installed from the build tree into a fresh venv and its tests run against
#     the installed daemon.
#   tests/install/run.sh deb BUILD_DIR      (scripts/test, as root)
#     scripts/package's .debs inspected (dpkg-deb --info/--contents), installed (dpkg -i, then
#     apt-get -f install), checked (versions, user, token, systemd-analyze verify, the daemon run as
#     the unit runs it), purged, and what the purge left checked. Skips (exit 77) with the reason
#     when not root or without dpkg.
#
# Each check prints "ok" or "FAIL" with what it found; the exit status is 1 when any failed.
set -euo pipefail

mode="${1:-}"
build="${2:-}"
if [ -z "$mode" ] || [ -z "$build" ] || [ ! -f "$build/CMakeCache.txt" ]; then
  echo "usage: tests/install/run.sh prefix|deb BUILD_DIR (a configured and built build tree)" >&2
  exit 2
fi
source_dir="$(cd "$(dirname "$0")/../.." && pwd)"
build="$(cd "$build" && pwd)"
version=$(sed -n 's/^CMAKE_PROJECT_VERSION:STATIC=//p' "$build/CMakeCache.txt")
[ -n "$version" ] || { echo "no CMAKE_PROJECT_VERSION in $build/CMakeCache.txt" >&2; exit 2; }

failures=0
ok() { echo "ok   $*"; }
fail() { echo "FAIL $*"; failures=$((failures + 1)); }
# check DESCRIPTION COMMAND...: ok when the command succeeds.
check() {
  local what="$1"
  shift
  if "$@"; then ok "$what"; else fail "$what"; fi
}
# same WHAT GOT EXPECTED
same() {
  if [ "$2" = "$3" ]; then ok "$1: $2"; else fail "$1: got '$2', expected '$3'"; fi
}
elapsed() { echo "$(( $(date +%s) - start_s )) s"; }
start_s=$(date +%s)

work=$(mktemp -d "${TMPDIR:-/tmp}/scenewatch-install-test-XXXXXX")
daemon_pid=
debs_installed=
cleanup() {
  if [ -n "$daemon_pid" ] && kill -0 "$daemon_pid" 2>/dev/null; then kill -TERM "$daemon_pid" 2>/dev/null || true; fi
  # A test stopped half-way leaves no package installed behind it.
  if [ -n "$debs_installed" ]; then dpkg --purge scenewatch-dev python3-scenewatch scenewatch >/dev/null 2>&1 || true; fi
  rm -rf "$work"
}
trap cleanup EXIT

# Waits for "listening on 127.0.0.1:PORT" in FILE; prints PORT.
wait_port() {
  local out="$1" pid="$2" port=
  for _ in $(seq 1 300); do
    port=$(sed -n 's/^listening on 127\.0\.0\.1:\([0-9][0-9]*\)$/\1/p' "$out")
    [ -n "$port" ] && { echo "$port"; return 0; }
    kill -0 "$pid" 2>/dev/null || return 1
    sleep 0.1
  done
  return 1
}

# ------------------------------------------------------------------------------------------------
run_prefix() {
  local prefix="$work/prefix"
  echo "== cmake --install $build --prefix $prefix"
  cmake --install "$build" --prefix "$prefix" >"$work/install.log" 2>&1 || { cat "$work/install.log"; fail "cmake --install"; return; }
  ok "cmake --install: $(grep -c '^-- Installing' "$work/install.log") files"
  local f
  for f in bin/scenewatchd bin/scenewatch bin/scenewatch-sim etc/scenewatch/scenewatchd.yaml etc/scenewatch/ontology.yaml \
           share/scenewatch/scenarios/cup_added.yaml share/scenewatch/proto/scenewatch.proto \
           lib/systemd/system/scenewatchd.service include/scenewatch/pipeline/working_memory.h \
           include/scenewatch/proto/scenewatch.pb.h lib/python3/dist-packages/scenewatch/scenewatch_pb2.py; do
    check "installed $f" test -f "$prefix/$f"
  done
  # The libraries' folder is GNUInstallDirs' (lib, or lib/<multiarch> for the prefix /usr).
  for f in libscenewatch_pipeline.a scenewatchConfig.cmake; do
    check "installed $f" test -n "$(find "$prefix" -name "$f")"
  done
  check "the unit runs $prefix/bin/scenewatchd with $prefix/etc/scenewatch/scenewatchd.yaml" \
    grep -q "^ExecStart=$prefix/bin/scenewatchd --config $prefix/etc/scenewatch/scenewatchd.yaml " "$prefix/lib/systemd/system/scenewatchd.service"

  # What the hidden run needs from the source tree, copied out first: the consumer project, and the
  # Python client's tests with the files they read (examples, sample clouds).
  mkdir -p "$work/src/clients/python"
  cp -r "$source_dir/tests/install/consumer" "$work/consumer"
  cp -r "$source_dir/clients/python/tests" "$source_dir/clients/python/examples" "$work/src/clients/python/"
  cp -r "$source_dir/sample_clouds" "$work/src/"

  echo "== pip install of the Python client (build tree, offline, no build isolation) into a fresh venv"
  # From a copy of build/clients/python: pip builds in place, and the build tree stays as it was.
  cp -r "$build/clients/python" "$work/python-client"
  # A build tree packaged before this change kept setuptools' build/ from then: installing it would
  # install that old copy of the client instead of this one.
  rm -rf "$work/python-client/build" "$work/python-client"/*.egg-info
  /usr/bin/python3 -m venv --system-site-packages "$work/venv"
  if "$work/venv/bin/python" -m pip install --no-build-isolation --no-index --no-cache-dir --quiet "$work/python-client" \
       >"$work/pip.log" 2>&1; then
    ok "pip install (a copy of) $build/clients/python"
  else
    cat "$work/pip.log"
    fail "pip install (a copy of) $build/clients/python"
  fi

  # The rest runs with the source and build trees hidden when a private mount namespace can be had
  # (root, or a kernel allowing it): a tmpfs over each, so nothing installed can reach into them.
  local hide=()
  hide_trees=
  if unshare --mount true 2>/dev/null; then
    hide=(unshare --mount --propagation private)
    hide_trees=1
    echo "== from the prefix, with $source_dir and $build hidden (a private mount namespace)"
  else
    echo "== from the prefix (no private mount namespace here: the source and build trees stay visible;" \
         "the paths the daemon logs show what it read)"
  fi
  export prefix work version source_dir build hide_trees
  "${hide[@]}" bash -c "$(declare -f ok fail check same wait_port hidden_checks); hidden_checks" || failures=$((failures + $?))
}

# Runs inside the namespace; returns the number of failures.
hidden_checks() {
  set -uo pipefail
  local failures=0
  # Hide the trees (only inside this namespace); the build tree may lie inside the source tree.
  if [ -n "$hide_trees" ]; then
    mount -t tmpfs none "$build" && mount -t tmpfs none "$source_dir" || { fail "hiding the trees"; return 1; }
    if [ -e "$source_dir/CMakeLists.txt" ] || [ -e "$build/CMakeCache.txt" ]; then fail "the trees are still visible"; fi
  fi
  cd "$work"
  export PATH="$prefix/bin:/usr/bin:/bin" HOME="$work/home"
  mkdir -p "$HOME"

  same "scenewatchd --version" "$(scenewatchd --version)" "scenewatchd $version"
  same "scenewatch --version" "$(scenewatch --version)" "scenewatch $version"
  same "scenewatch-sim --version" "$(scenewatch-sim --version)" "scenewatch-sim $version"

  # The simulator's shipped scenario (found in PREFIX/share/scenewatch/scenarios), then replayed
  # offline with the installed config. Ground truth: a cup is put on the table between the phases.
  if scenewatch-sim render cup_added --width 320 --height 240 --frames 20 --out "$work/scene" --quiet >"$work/sim.log" 2>&1; then
    ok "scenewatch-sim render cup_added (the installed scenarios)"
  else
    cat "$work/sim.log"; fail "scenewatch-sim render cup_added"
  fi
  if scenewatch replay "$work/scene/before" "$work/scene/after" --config "$prefix/etc/scenewatch/scenewatchd.yaml" --json \
       >"$work/replay.jsonl" 2>"$work/replay.log"; then
    ok "scenewatch replay of the rendered scenario"
  else
    cat "$work/replay.log"; fail "scenewatch replay"
  fi
  local added
  added=$(grep -c '"kind": *"OBJECT_ADDED"' "$work/replay.jsonl" || true)
  if [ "$added" -ge 1 ]; then ok "the replay reports the cup: $added OBJECT_ADDED"; else
    tail -3 "$work/replay.jsonl"; fail "the replay reports no OBJECT_ADDED (the cup put on the table)"; fi

  # The daemon with no --config: it reads PREFIX/etc/scenewatch/scenewatchd.yaml.
  scenewatchd --port 0 >"$work/daemon.out" 2>"$work/daemon.log" &
  local pid=$! port
  if port=$(wait_port "$work/daemon.out" "$pid"); then
    ok "scenewatchd (no --config) listening on $port"
    check "it read $prefix/etc/scenewatch/scenewatchd.yaml" grep -q "config: $prefix/etc/scenewatch/scenewatchd.yaml$" "$work/daemon.log"
    check "its classes are $prefix/etc/scenewatch/ontology.yaml" grep -q "object classes: .*($prefix/etc/scenewatch/ontology.yaml" "$work/daemon.log"
    check "it made the token ~/.scenewatch/token (mode 600)" test "$(stat -c %a "$HOME/.scenewatch/token" 2>/dev/null)" = 600
    same "scenewatch health: version" "$(scenewatch --port "$port" health | sed -n 's/^ok: scenewatchd \([^ ]*\) at .*/\1/p')" "$version"
  else
    cat "$work/daemon.log"; fail "scenewatchd (no --config) did not start"
  fi

  echo "== consumer project: find_package(scenewatch) against $prefix"
  if cmake -S "$work/consumer" -B "$work/consumer-build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
       >"$work/consumer-configure.log" 2>&1; then
    ok "consumer configured (C++ only; $(grep -c 'enabling the C language' "$work/consumer-configure.log") note on enabling C)"
    if cmake --build "$work/consumer-build" -j "${SCENEWATCH_JOBS:-2}" >"$work/consumer-build.log" 2>&1; then
      ok "consumer built"
      if [ -n "${port:-}" ]; then
        "$work/consumer-build/consumer" "$port" | sed 's/^/     /'
        check "consumer: a WorkingMemory processed a frame, the daemon answered" test "${PIPESTATUS[0]}" -eq 0
      fi
    else
      tail -30 "$work/consumer-build.log"; fail "consumer build"
    fi
  else
    cat "$work/consumer-configure.log"; fail "consumer configure"
  fi
  [ -n "${pid:-}" ] && kill -TERM "$pid" 2>/dev/null && wait "$pid" 2>/dev/null

  echo "== the Python client from the venv, its tests against the installed daemon"
  local py="$work/venv/bin/python"
  same "scenewatch.__version__" "$("$py" -c 'import scenewatch; print(scenewatch.__version__)' 2>&1)" "$version"
  check "imported from the venv" "$py" -c "import scenewatch, sys; sys.exit(not scenewatch.__file__.startswith('$work/venv/'))"
  if (cd "$work/src/clients/python/tests" && env -u PYTHONPATH PYTHONDONTWRITEBYTECODE=1 SCENEWATCHD="$prefix/bin/scenewatchd" \
        SCENEWATCH_CLI="$prefix/bin/scenewatch" SCENEWATCH_SIM="$prefix/bin/scenewatch-sim" SCENEWATCH_SOURCE_DIR="$work/src" \
        SCENEWATCH_DATA_DIR="$work/no-data" "$py" -m unittest test_client test_examples >"$work/pytest.log" 2>&1); then
    ok "Python client tests: $(grep -E '^Ran [0-9]+ tests' "$work/pytest.log")"
  else
    tail -40 "$work/pytest.log"; fail "Python client tests"
  fi
  return "$failures"
}

# ------------------------------------------------------------------------------------------------
run_deb() {
  if ! command -v dpkg >/dev/null 2>&1; then echo "install test (deb): skipped: no dpkg on this machine"; exit 77; fi
  if [ "$(id -u)" -ne 0 ]; then echo "install test (deb): skipped: dpkg -i needs root (run scripts/test as root)"; exit 77; fi
  local p
  for p in scenewatch scenewatch-dev python3-scenewatch; do
    if dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "installed"; then
      echo "install test (deb): the package $p is installed already; remove it first (dpkg --purge $p)" >&2
      exit 1
    fi
  done
  local had_user=0 had_state=0
  getent passwd scenewatch >/dev/null && had_user=1
  [ -e /var/lib/scenewatch ] && had_state=1

  echo "== scripts/package"
  local out="$build/packages"
  "$source_dir/scripts/package" "$build" >"$work/package.log" 2>&1 || { tail -30 "$work/package.log"; fail "scripts/package"; return; }
  local arch
  arch=$(dpkg --print-architecture)
  local runtime="$out/scenewatch_${version}_${arch}.deb" dev="$out/scenewatch-dev_${version}_${arch}.deb"
  local python="$out/python3-scenewatch_${version}_all.deb" wheel="$out/scenewatch-${version}-py3-none-any.whl"
  for p in "$runtime" "$dev" "$python" "$wheel"; do check "made $(basename "$p") ($(du -h "$p" 2>/dev/null | cut -f1))" test -f "$p"; done
  check "the wheel holds the generated scenewatch_pb2.py" sh -c "/usr/bin/python3 -m zipfile -l '$wheel' | grep -q scenewatch/scenewatch_pb2.py"

  echo "== dpkg-deb --info / --contents"
  dpkg-deb --info "$runtime" | sed 's/^/     /'
  local depends
  depends=$(dpkg-deb -f "$runtime" Depends)
  check "Depends from dpkg-shlibdeps: libpcl, liboctomap, libopencv, libprotobuf ..." \
    sh -c "echo '$depends' | grep -q libpcl && echo '$depends' | grep -q liboctomap && echo '$depends' | grep -q libopencv && echo '$depends' | grep -q libprotobuf"
  dpkg-deb --contents "$runtime" >"$work/runtime.contents"
  sed 's/^/     /' "$work/runtime.contents"
  for f in ./usr/bin/scenewatchd ./etc/scenewatch/scenewatchd.yaml ./lib/systemd/system/scenewatchd.service \
           ./usr/share/doc/scenewatch/copyright ./usr/share/scenewatch/proto/scenewatch.proto \
           ./usr/share/doc/scenewatch/README.md ./usr/share/doc/scenewatch/docs/events.md; do
    check "scenewatch holds $f" grep -q " $f\$" "$work/runtime.contents"
  done
  check "conffiles list /etc/scenewatch/scenewatchd.yaml" sh -c "dpkg-deb --ctrl-tarfile '$runtime' | tar -xO ./conffiles | grep -qx /etc/scenewatch/scenewatchd.yaml"
  for p in "$dev" "$python"; do
    dpkg-deb --info "$p" | sed 's/^/     /'
    dpkg-deb --contents "$p" >"$work/$(basename "$p").contents"
    sed 's/^/     /' "$work/$(basename "$p").contents"
  done
  check "scenewatch-dev holds the CMake package and working_memory.h" \
    sh -c "grep -q ' ./usr/lib/cmake/scenewatch/scenewatchConfig.cmake$' '$work/$(basename "$dev").contents' &&
           grep -q ' ./usr/include/scenewatch/pipeline/working_memory.h$' '$work/$(basename "$dev").contents'"
  check "python3-scenewatch holds scenewatch_pb2.py" \
    grep -q ' ./usr/lib/python3/dist-packages/scenewatch/scenewatch_pb2.py$' "$work/$(basename "$python").contents"

  echo "== dpkg -i, apt-get -f install"
  debs_installed=1
  if dpkg -i "$runtime" "$dev" "$python" >"$work/dpkg.log" 2>&1; then
    ok "dpkg -i"
  else
    echo "     dpkg -i left dependencies to resolve:"; sed 's/^/     /' "$work/dpkg.log" | tail -10
  fi
  if DEBIAN_FRONTEND=noninteractive apt-get -f install -y -qq >"$work/apt.log" 2>&1; then ok "apt-get -f install"; else
    tail -20 "$work/apt.log"; fail "apt-get -f install"; fi
  for p in scenewatch scenewatch-dev python3-scenewatch; do
    same "dpkg status of $p" "$(dpkg-query -W -f='${Status} ${Version}' "$p" 2>/dev/null)" "install ok installed $version"
  done
  same "/usr/bin/scenewatchd --version" "$(/usr/bin/scenewatchd --version)" "scenewatchd $version"
  same "python3-scenewatch: scenewatch.__version__" "$(cd / && /usr/bin/python3 -c 'import scenewatch; print(scenewatch.__version__)')" "$version"
  check "user scenewatch (system, no login)" sh -c "getent passwd scenewatch | grep -q ':/var/lib/scenewatch:/usr/sbin/nologin$'"
  same "/var/lib/scenewatch" "$(stat -c '%U %a' /var/lib/scenewatch)" "scenewatch 750"
  same "token folder" "$(stat -c '%U %a' /var/lib/scenewatch/.scenewatch)" "scenewatch 700"
  same "token" "$(stat -c '%U %a %s' /var/lib/scenewatch/.scenewatch/token)" "scenewatch 600 65"
  local unit=/lib/systemd/system/scenewatchd.service
  if systemd-analyze verify "$unit" >"$work/verify.log" 2>&1 && [ ! -s "$work/verify.log" ]; then
    ok "systemd-analyze verify $unit (no warnings)"
  else
    sed 's/^/     /' "$work/verify.log"; fail "systemd-analyze verify $unit"; fi
  check "the unit is enabled (multi-user.target wants it)" test -L /etc/systemd/system/multi-user.target.wants/scenewatchd.service
  check "the unit: Restart=on-failure, User=scenewatch" sh -c "grep -qx Restart=on-failure $unit && grep -qx User=scenewatch $unit"

  # systemd is not running here (a container or CI machine): the daemon is run the way the unit runs
  # it, as its user with its ExecStart, on a free port, to see the postinst's token accepted.
  local exec_start
  exec_start=$(sed -n 's/^ExecStart=//p' "$unit")
  # shellcheck disable=SC2086
  (cd / && exec runuser -u scenewatch -- $exec_start --port 0 >"$work/unit.out" 2>"$work/unit.log") &
  daemon_pid=$!
  local port
  if port=$(wait_port "$work/unit.out" "$daemon_pid"); then
    ok "scenewatchd as the unit runs it (user scenewatch): listening on $port"
    check "it accepted the postinst's token" grep -q "need the token in /var/lib/scenewatch/.scenewatch/token" "$work/unit.log"
    if runuser -u scenewatch -- /usr/bin/scenewatch --port "$port" --token-file /var/lib/scenewatch/.scenewatch/token save \
         >"$work/save.out" 2>&1; then
      ok "scenewatch save with the token (as user scenewatch)"
    else
      cat "$work/save.out"; fail "scenewatch save with the token"
    fi
    kill -TERM "$daemon_pid"; wait "$daemon_pid" 2>/dev/null || true
    daemon_pid=
    check "the model was saved in /var/lib/scenewatch" test -L /var/lib/scenewatch/current
  else
    cat "$work/unit.log"; fail "scenewatchd as the unit runs it did not start"
  fi

  echo "== dpkg --purge"
  if dpkg --purge scenewatch-dev python3-scenewatch scenewatch >"$work/purge.log" 2>&1; then ok "dpkg --purge"; else
    cat "$work/purge.log"; fail "dpkg --purge"; fi
  debs_installed=
  for p in /usr/bin/scenewatchd /etc/scenewatch "$unit" /etc/systemd/system/multi-user.target.wants/scenewatchd.service \
           /var/lib/scenewatch/.scenewatch /usr/lib/cmake/scenewatch /usr/lib/python3/dist-packages/scenewatch \
           /usr/share/doc/scenewatch; do
    check "purged: $p" test ! -e "$p"
  done
  check "left: the model directory /var/lib/scenewatch with the saved model" test -L /var/lib/scenewatch/current
  check "no scenewatch package left in dpkg's database" sh -c "! dpkg -l 'scenewatch*' 'python3-scenewatch' 2>/dev/null | grep -q '^[a-z][a-z] '"
  # Left by design, not by the test: the user (docs/install.md). This machine gets back
  # what it had before the test.
  [ "$had_state" -eq 0 ] && rm -rf /var/lib/scenewatch
  [ "$had_user" -eq 0 ] && userdel scenewatch 2>/dev/null || true
}

case "$mode" in
  prefix) run_prefix ;;
  deb) run_deb ;;
  *) echo "usage: tests/install/run.sh prefix|deb BUILD_DIR" >&2; exit 2 ;;
esac
echo "install test ($mode): $failures failed, $(elapsed)"
[ "$failures" -eq 0 ]
