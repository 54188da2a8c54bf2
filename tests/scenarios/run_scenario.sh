#!/usr/bin/env bash
# CTest driver of one scenario script: starts scenewatchd on a free loopback port with a fresh
# model directory and token, runs `scenewatch replay SCRIPT --check` against it, stops it.
# Usage: run_scenario.sh BUILD_DIR SOURCE_DIR SCRIPT
set -euo pipefail
build="$1" source="$2" script="$3"
work="$(mktemp -d)"
trap 'kill "$daemon" 2>/dev/null || true; wait "$daemon" 2>/dev/null || true; rm -rf "$work"' EXIT
"$build/apps/scenewatchd/scenewatchd" --config "$source/config/scenewatchd.yaml" --port 0 \
  --model-dir "$work/model" --token-file "$work/token" >"$work/out" 2>"$work/log" &
daemon=$!
for _ in $(seq 1 100); do
  grep -q "listening on" "$work/out" 2>/dev/null && break
  kill -0 "$daemon" 2>/dev/null || { echo "scenewatchd did not start:"; cat "$work/log"; exit 1; }
  sleep 0.1
done
port="$(grep -o 'listening on [0-9.]*:[0-9]*' "$work/out" | sed 's/.*://')"
[ -n "$port" ] || { echo "scenewatchd printed no port:"; cat "$work/out" "$work/log"; exit 1; }
"$build/apps/scenewatch/scenewatch" replay "$script" --check --port "$port" --token-file "$work/token"
