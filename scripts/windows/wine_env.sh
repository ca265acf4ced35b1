# Sourced by the Windows steps (CI, by hand): a private Wine prefix that runs Rust's
# Windows binaries. Wine 8 lacks ProcessPrng, which Rust's standard library imports, so a
# small bcryptprimitives.dll (prng_shim.c, built with mingw) goes into the prefix and is
# preferred to Wine's own. Needs x86_64-w64-mingw32-gcc and wine; sets WINEPREFIX,
# WINEDEBUG, WINEDLLOVERRIDES and cargo's runner for x86_64-pc-windows-gnu.

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
export WINEPREFIX="${WINEPREFIX:-$root/target/wine-prefix}"
export WINEDEBUG=-all
export WINEDLLOVERRIDES="bcryptprimitives=n,b;mscoree,mshtml="
export CARGO_TARGET_X86_64_PC_WINDOWS_GNU_RUNNER=wine
if [ ! -f "$WINEPREFIX/system.reg" ]; then
  mkdir -p "$WINEPREFIX"
  wineboot --init >/dev/null 2>&1 || true
  wineserver --wait || true
fi
system32="$WINEPREFIX/drive_c/windows/system32"
if [ ! -f "$system32/bcryptprimitives.dll" ] || [ "$here/prng_shim.c" -nt "$system32/bcryptprimitives.dll" ] \
   || ! grep -q ProcessPrng "$system32/bcryptprimitives.dll" 2>/dev/null; then
  x86_64-w64-mingw32-gcc -O2 -shared -o "$system32/bcryptprimitives.dll" \
    "$here/prng_shim.c" "$here/prng_shim.def" -ladvapi32
fi
