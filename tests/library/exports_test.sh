#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# libwhitted.so exports the public API and nothing else (docs/library.md): every dynamic symbol
# it defines is in whitted::api (functions, typeinfo, vtables), none of the private code, Embree,
# TBB, libyaml or OpenColorIO; and its SONAME carries MAJOR.MINOR (before 1.0 a minor version
# may break the ABI).
# Usage: exports_test.sh LIBRARY VERSION
set -euo pipefail
lib=$1 version=$2
soname=$(readelf -d "$lib" | sed -n 's/.*Library soname: \[\(.*\)\]/\1/p')
want="libwhitted.so.$(echo "$version" | cut -d. -f1,2)"
[ "$soname" = "$want" ] || { echo "FAIL: SONAME '$soname', expected '$want'"; exit 1; }
symbols=$(nm -DC --defined-only "$lib" | cut -d' ' -f3-)
count=$(printf '%s\n' "$symbols" | grep -c . || true)
[ "$count" -gt 10 ] || { echo "FAIL: only $count symbols exported"; exit 1; }
# Inline entities of the standard library itself (typeinfo of libstdc++'s internal bases, a
# static table in an inline function) may be exported too: libstdc++ declares namespace std with
# default visibility, and without link-time optimisation (the sanitizer build) they are kept as
# weak, merged definitions. They are the standard library's, not ours, so they are let through.
others=$(printf '%s\n' "$symbols" | grep -v 'whitted::api::' |
  grep -Ev '^((typeinfo|typeinfo name|vtable) for )?std::' || true)
if [ -n "$others" ]; then
  echo "FAIL: symbols outside whitted::api:"; printf '%s\n' "$others" | head -20; exit 1
fi
for needed in whitted::api::load_scene_file whitted::api::render whitted::api::write_image whitted::api::check \
              whitted::api::version whitted::api::SceneBuilder::build; do
  # A here-string, not a pipe: grep -q stops at the first match, and under pipefail a later
  # write of printf's into the closed pipe (SIGPIPE) would fail the pipeline though the symbol
  # is there. Likely what failed this check once in the front door's root; not reproduced on
  # the host (0 of 300 runs).
  grep -q -- "$needed" <<<"$symbols" || { echo "FAIL: $needed not exported"; exit 1; }
done
echo "PASS: $count symbols, all in whitted::api; SONAME $soname"
