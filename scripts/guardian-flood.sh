#!/usr/bin/env bash
# The guardian on a flooding line (issue 35, finding 5): a stand-in window (the pendant's
# own Session through a guardian, see crates/core/examples/guardian_flood.rs) on a TCP
# bridge to `xsel-sim --tcp` that adds junk CR LF lines to what the simulator sends, a
# continuous jog, `kill -STOP` of the window: prints the time to the 238H on the line and
# the guardian's resident memory after the flood, min/median/max. Linux only.
#
# scripts/guardian-flood.sh [RUNS] [SECONDS] [JUNK_BYTES_PER_SEC]   (defaults 5 30 2000000)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p xsel-pendant-core --example guardian_flood
cargo build --bin xsel-sim
dir=$(mktemp -d)
mkfifo "$dir/console"
target/debug/xsel-sim --tcp 127.0.0.1:0 --ready <"$dir/console" >"$dir/sim.out" 2>"$dir/sim.err" &
sim=$!
exec 3>"$dir/console" # the simulator's console stays open while this runs
trap 'kill "$sim" 2>/dev/null || true; exec 3>&-; rm -rf "$dir"' EXIT
addr=""
for _ in $(seq 100); do
    addr=$(head -n1 "$dir/sim.out" 2>/dev/null || true)
    [ -n "$addr" ] && break
    sleep 0.1
done
[ -n "$addr" ] || { echo "xsel-sim did not start" >&2; cat "$dir/sim.err" >&2; exit 1; }
echo "xsel-sim --tcp $addr --ready"
target/release/examples/guardian_flood "$addr" "$@"
