#!/usr/bin/env bash
# Flash and static-RAM bytes of a firmware ELF (section sizes from readelf, which reads any
# ELF). flash = .vector_table + .text + .rodata + .data (its load image); ram = .data + .bss
# + .uninit. Prints "flash=N ram=M".
set -euo pipefail
flash=0
ram=0
while read -r name size; do
  bytes=$((16#$size))
  case "$name" in
    .vector_table|.text|.rodata) flash=$((flash + bytes)) ;;
    .data) flash=$((flash + bytes)); ram=$((ram + bytes)) ;;
    .bss|.uninit) ram=$((ram + bytes)) ;;
  esac
done < <(readelf -S -W "$1" | grep -E '^ *\[ *[0-9]+\] +\.' | sed -E 's/^ *\[ *[0-9]+\] +//' | awk '{ print $1, $5 }')
echo "flash=$flash ram=$ram"
