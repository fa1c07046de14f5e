#!/bin/sh
# Installs pleat like a C library under a prefix:
#
#   sh packaging/install.sh --prefix /usr/local
#
#   PREFIX/lib/libpleat.so.X.Y.Z                 the shared library (SONAME libpleat.so.X)
#   PREFIX/lib/libpleat.so.X -> libpleat.so.X.Y.Z, libpleat.so -> libpleat.so.X
#   PREFIX/lib/libpleat.a                        the static library
#   PREFIX/include/pleat.h, pleat.hpp            the C header and the C++ RAII header
#   PREFIX/lib/pkgconfig/pleat.pc                `pkg-config --cflags --libs pleat`
#   PREFIX/lib/cmake/pleat/pleatConfig*.cmake    `find_package(pleat)` -> pleat::pleat
#
# It builds the library with `cargo build --release --lib` first (a no-op when `cargo build
# --release` already ran), then copies cargo's artifacts; it needs only a POSIX shell and
# coreutils. Why not cargo-c's `cargo cinstall`: see docs/design-notes-lod.md, "Packaging".
#
# Options:
#   --prefix DIR       installation prefix (default /usr/local)
#   --libdir DIR       library directory (default PREFIX/lib; e.g. PREFIX/lib/x86_64-linux-gnu)
#   --includedir DIR   header directory (default PREFIX/include)
#   --destdir DIR      staging root prepended to every path written (default $DESTDIR), for
#                      distribution packages; the installed files still name PREFIX
#   --target-dir DIR   cargo's target directory (default $CARGO_TARGET_DIR, else ./target)
#   --profile NAME     cargo profile whose artifacts are installed (default release)
#   --no-build         do not run cargo; install the artifacts already built
#   --strip            strip debug information from the installed libraries
#   -- ARGS...         passed to `cargo build` (e.g. -- --no-default-features --features lod)
set -eu

die() { echo "install.sh: $*" >&2; exit 1; }

root=$(cd "$(dirname "$0")/.." && pwd)
prefix=/usr/local
libdir=
includedir=
destdir=${DESTDIR:-}
target_dir=${CARGO_TARGET_DIR:-$root/target}
profile=release
build=1
strip=0
while [ $# -gt 0 ]; do
  case $1 in
    --prefix) prefix=${2:?--prefix needs a value}; shift 2 ;;
    --prefix=*) prefix=${1#*=}; shift ;;
    --libdir) libdir=${2:?--libdir needs a value}; shift 2 ;;
    --libdir=*) libdir=${1#*=}; shift ;;
    --includedir) includedir=${2:?--includedir needs a value}; shift 2 ;;
    --includedir=*) includedir=${1#*=}; shift ;;
    --destdir) destdir=${2:?--destdir needs a value}; shift 2 ;;
    --destdir=*) destdir=${1#*=}; shift ;;
    --target-dir) target_dir=${2:?--target-dir needs a value}; shift 2 ;;
    --target-dir=*) target_dir=${1#*=}; shift ;;
    --profile) profile=${2:?--profile needs a value}; shift 2 ;;
    --profile=*) profile=${1#*=}; shift ;;
    --no-build) build=0; shift ;;
    --strip) strip=1; shift ;;
    --) shift; break ;;
    -h|--help) sed -n '2,/^set -eu/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) die "unknown option $1 (see --help)" ;;
  esac
done

case $prefix in /*) ;; *) prefix=$(mkdir -p "$prefix" && cd "$prefix" && pwd) ;; esac
prefix=${prefix%/}
[ -n "$libdir" ] || libdir=$prefix/lib
[ -n "$includedir" ] || includedir=$prefix/include
case $libdir in /*) ;; *) die "--libdir must be absolute" ;; esac
case $includedir in /*) ;; *) die "--includedir must be absolute" ;; esac

# The version is the [package] version of Cargo.toml (also what pleat_version() returns).
version=$(sed -n '/^\[package\]/,/^\[/s/^version *= *"\([^"]*\)".*/\1/p' "$root/Cargo.toml" | head -n 1)
[ -n "$version" ] || die "no version in $root/Cargo.toml"
major=${version%%.*}
rest=${version#*.}
minor=${rest%%.*}

if [ "$build" = 1 ]; then
  command -v cargo >/dev/null 2>&1 || die "cargo not found (install Rust, or pass --no-build)"
  if [ "$profile" = release ]; then set -- --release "$@"; else set -- --profile "$profile" "$@"; fi
  echo "install.sh: cargo build --lib $*"
  (cd "$root" && CARGO_TARGET_DIR=$target_dir cargo build --lib "$@")
fi

out=$target_dir/$profile
[ -f "$out/libpleat.so" ] || die "$out/libpleat.so not found (build first or drop --no-build)"
[ -f "$out/libpleat.a" ] || die "$out/libpleat.a not found"

# The SONAME build.rs gave the library; the real file is named after the full version.
soname=
if command -v readelf >/dev/null 2>&1; then
  soname=$(readelf -d "$out/libpleat.so" | sed -n 's/.*(SONAME).*\[\(.*\)\].*/\1/p')
elif command -v objdump >/dev/null 2>&1; then
  soname=$(objdump -p "$out/libpleat.so" | awk '$1 == "SONAME" { print $2 }')
fi
[ -n "$soname" ] || soname=libpleat.so.$major
soversion=${soname#libpleat.so.}
real=libpleat.so.$version

# Path from PREFIX/<libdir>/cmake/pleat back to PREFIX, so the CMake config is relocatable.
rel() { # rel DIR: DIR relative to $prefix, or die
  case $1 in "$prefix"/*) echo "${1#"$prefix"/}" ;; *) die "$1 is not under --prefix $prefix" ;; esac
}
libdir_rel=$(rel "$libdir")
includedir_rel=$(rel "$includedir")
up=../..
r=$libdir_rel
while [ -n "$r" ]; do
  up=$up/..
  case $r in */*) r=${r#*/} ;; *) r= ;; esac
done

lib=$destdir$libdir
inc=$destdir$includedir
mkdir -p "$lib/pkgconfig" "$lib/cmake/pleat" "$inc"

install_file() { # install_file MODE SRC DST: atomic copy (a running program keeps the old inode)
  cp "$2" "$3.tmp.$$" && chmod "$1" "$3.tmp.$$" && mv -f "$3.tmp.$$" "$3"
}
install_file 755 "$out/libpleat.so" "$lib/$real"
install_file 644 "$out/libpleat.a" "$lib/libpleat.a"
if [ "$strip" = 1 ]; then
  command -v strip >/dev/null 2>&1 || die "--strip: strip not found"
  strip --strip-debug "$lib/$real" "$lib/libpleat.a"
fi
[ "$soname" = "$real" ] || ln -sf "$real" "$lib/$soname"
ln -sf "$soname" "$lib/libpleat.so"
install_file 644 "$root/include/pleat.h" "$inc/pleat.h"
install_file 644 "$root/bindings/cpp/pleat.hpp" "$inc/pleat.hpp"

# Rust's std needs these when linked statically (`rustc --print native-static-libs`, Linux);
# -lstdc++ for xatlas (C++, feature `bake`), which the `cc` crate compiles into the library.
native_static_libs="-lstdc++ -lgcc_s -lutil -lrt -lpthread -lm -ldl -lc"
ptr_bytes=$(( $(getconf LONG_BIT 2>/dev/null || echo 64) / 8 ))
subst() { # subst TEMPLATE DST
  sed -e "s|@PREFIX@|$prefix|g" -e "s|@LIBDIR@|$libdir|g" -e "s|@INCLUDEDIR@|$includedir|g" \
      -e "s|@LIBDIR_REL@|$libdir_rel|g" -e "s|@INCLUDEDIR_REL@|$includedir_rel|g" \
      -e "s|@CMAKE_TO_PREFIX@|$up|g" -e "s|@VERSION@|$version|g" \
      -e "s|@VERSION_MAJOR@|$major|g" -e "s|@VERSION_MINOR@|$minor|g" \
      -e "s|@SONAME@|$soname|g" -e "s|@SOVERSION@|$soversion|g" -e "s|@SHARED_REAL@|$real|g" \
      -e "s|@NATIVE_STATIC_LIBS@|$native_static_libs|g" -e "s|@SIZEOF_VOID_P@|$ptr_bytes|g" \
      "$root/packaging/$1" > "$2.tmp.$$"
  mv -f "$2.tmp.$$" "$2"
}
subst pleat.pc.in "$lib/pkgconfig/pleat.pc"
subst pleatConfig.cmake.in "$lib/cmake/pleat/pleatConfig.cmake"
subst pleatConfigVersion.cmake.in "$lib/cmake/pleat/pleatConfigVersion.cmake"

echo "install.sh: installed pleat $version (SONAME $soname) under $destdir$prefix:"
for f in "$lib/$real" "$lib/$soname" "$lib/libpleat.so" "$lib/libpleat.a" "$inc/pleat.h" \
         "$inc/pleat.hpp" "$lib/pkgconfig/pleat.pc" "$lib/cmake/pleat/pleatConfig.cmake" \
         "$lib/cmake/pleat/pleatConfigVersion.cmake"; do
  echo "  $f"
done
