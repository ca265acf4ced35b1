#!/usr/bin/env bash
# The release artefacts: the pendant, xsel-sim and rmc-sim for Linux (x86_64) and Windows
# (x86_64, cross-built with mingw-w64), each zipped with the README and the licences into
# target/dist/xsel-pendant-VERSION-{linux,windows}-x86_64.zip. No installer: unzip and run.
# The pendant is built with both renderers (the `wgpu` feature).
#
#   scripts/package.sh                  build (release) and package
#   scripts/package.sh --profile dev    package the dev build's binaries (CI does this after
#                                       its test builds, to keep the script working without
#                                       a third build; not for users)
#   scripts/package.sh --no-build       package what is built
set -euo pipefail
cd "$(dirname "$0")/.."

profile=release
build=1
while [ $# -gt 0 ]; do
  case "$1" in
    --profile) profile="$2"; shift 2 ;;
    --no-build) build=0; shift ;;
    *) echo "package.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
dir_of() { # the target folder of a profile
  if [ "$profile" = dev ]; then echo debug; else echo "$profile"; fi
}
version=$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)
bins=(xsel-pendant xsel-sim rmc-sim)
dist=target/dist
mkdir -p "$dist"

package() { # platform, folder of the binaries, file suffix
  local platform="$1" from="$2" ext="$3"
  local name="xsel-pendant-$version-$platform"
  local stage="$dist/$name"
  rm -rf "$stage" "$stage.zip"
  mkdir -p "$stage"
  for b in "${bins[@]}"; do
    if [ ! -f "$from/$b$ext" ]; then
      echo "package.sh: $from/$b$ext is not built" >&2
      exit 1
    fi
    cp "$from/$b$ext" "$stage/"
  done
  cp README.md LICENSE-MIT LICENSE-APACHE "$stage/"
  (cd "$dist" && zip -q -r "$name.zip" "$name")
  rm -rf "$stage"
  echo "$dist/$name.zip: $(du -h "$dist/$name.zip" | cut -f1) (${bins[*]})"
}

if [ "$build" = 1 ]; then
  # The release zips carry the wgpu renderer too (`--renderer wgpu`, for a graphics
  # driver that fails with OpenGL); a first `cargo run --release` builds glow only.
  cargo build --profile "$profile" -p xsel-pendant --bins --features wgpu
  cargo build --profile "$profile" -p xsel-pendant --bins --features wgpu \
    --target x86_64-pc-windows-gnu
fi
package linux-x86_64 "target/$(dir_of)" ""
package windows-x86_64 "target/x86_64-pc-windows-gnu/$(dir_of)" ".exe"
