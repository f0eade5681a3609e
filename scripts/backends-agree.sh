#!/usr/bin/env bash
# Renders the checksum set (scripts/render-checksums.sh) once with every
# backend this processor runs (WHITTED_ISA, accel/kernel.rs) and fails
# unless all lists are identical: the backends give the same pictures bit
# for bit.
#
#   scripts/backends-agree.sh target/release/whitted
set -euo pipefail
whitted=$(realpath "$1")
cd "$(dirname "$0")/.."
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
isas=sse2
if grep -qw avx /proc/cpuinfo; then isas="$isas avx"; fi
if grep -qw avx2 /proc/cpuinfo && grep -qw fma /proc/cpuinfo; then isas="$isas avx2"; fi
first=
for isa in $isas; do
  WHITTED_ISA=$isa scripts/render-checksums.sh "$whitted" "$work/$isa" > "$work/$isa.txt"
  echo "WHITTED_ISA=$isa: $(wc -l < "$work/$isa.txt") checksums"
  if [ -z "$first" ]; then
    first=$isa
  elif ! diff "$work/$first.txt" "$work/$isa.txt"; then
    echo "WHITTED_ISA=$isa renders differently from WHITTED_ISA=$first" >&2
    exit 1
  fi
done
echo "every backend ($isas) renders the same pictures"
