#!/usr/bin/env bash
# The simulators as a user runs them, driven over loopback by clients of their own (in
# Python, not the project's codecs), and the pendant's text mode against the X-SEL one:
#   scripts/windows/smoke.sh DIR [RUNNER]
# DIR holds xsel-sim, rmc-sim and xsel-pendant (with .exe when RUNNER is wine). CI runs
# the Windows builds under Wine this way; on Linux, `scripts/windows/smoke.sh target/debug`.
set -euo pipefail
dir="$1"
runner="${2:-}"
ext=""
[ -n "$runner" ] && ext=".exe"
tmp=$(mktemp -d)
pids=()
# The servers read their consoles from a FIFO this script holds open (a closed stdin
# would end a console), and nothing else is left behind when it ends.
mkfifo "$tmp/console"
exec 3<>"$tmp/console"
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  exec 3>&-
  rm -rf "$tmp"
}
trap cleanup EXIT

# The first line a server prints, within 60 s (Wine starts slowly the first time).
first_line() { # file, pattern
  for _ in $(seq 600); do
    if grep -qE "$2" "$1" 2>/dev/null; then grep -oE "$2" "$1" | head -1; return; fi
    sleep 0.1
  done
  echo "smoke: no '$2' from the server:" >&2; cat "$1" >&2; exit 1
}

$runner "$dir/xsel-sim$ext" --tcp 127.0.0.1:0 --ready < "$tmp/console" > "$tmp/xsel.out" 2>&1 &
pids+=($!)
xsel=$(first_line "$tmp/xsel.out" '127\.0\.0\.1:[0-9]+')
$runner "$dir/rmc-sim$ext" --tcp 127.0.0.1:0 < "$tmp/console" > "$tmp/rmc.out" 2>&1 &
pids+=($!)
rmc=$(first_line "$tmp/rmc.out" '127\.0\.0\.1:[0-9]+')

python3 - "$xsel" "$rmc" <<'PY'
import socket, struct, sys

def connect(addr):
    host, port = addr.rsplit(":", 1)
    return socket.create_connection((host, int(port)), timeout=10)

# Format B: 215H system status, the checksum summed by hand.
body = b"!99215"
frame = body + b"%02X\r\n" % (sum(body) & 0xFF)
with connect(sys.argv[1]) as s:
    s.sendall(frame)
    reply = b""
    while not reply.endswith(b"\r\n"):
        reply += s.recv(256)
assert reply.startswith(b"#99215"), reply
print("xsel-sim answered 215H:", reply.strip().decode())

# Modbus/TCP: FC3, 116 registers from 4096 (axis 1's Status Bits..Command Velocity).
with connect(sys.argv[2]) as s:
    s.sendall(struct.pack(">HHHBBHH", 7, 0, 6, 1, 3, 4096, 116))
    reply = b""
    while len(reply) < 9 + 232:
        chunk = s.recv(512)
        assert chunk, reply
        reply += chunk
transaction, protocol, length, unit, function, count = struct.unpack(">HHHBBB", reply[:9])
assert (transaction, protocol, function, count) == (7, 0, 3, 232), reply[:9]
print("rmc-sim answered FC3 with", count // 2, "registers")
PY

out=$(timeout 120 $runner "$dir/xsel-pendant$ext" --headless --tcp "$xsel" 2>&1) || {
  echo "smoke: xsel-pendant --headless failed:" >&2; echo "$out" >&2; exit 1
}
echo "$out" | grep -q "servo on, homed" || { echo "smoke: no status from xsel-pendant:" >&2; echo "$out" >&2; exit 1; }
echo "xsel-pendant --headless read the simulator's status"
