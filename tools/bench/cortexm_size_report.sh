#!/usr/bin/env bash
# Memory report for Cortex-M ELF files, with the budget a board must fit:
#   code  .vectors, .text (with .rodata), .ARM.*, .init_array   <= 120 KiB
#   RAM   .data + .bss + the .stack reservation                  <= 32 KiB
# The model image (.cdcr_model) is reported on its own: it is flashed
# separately and sized by the model, not the firmware.
#
#   bash tools/bench/cortexm_size_report.sh build-m7/bin/cdcr_qemu_replay.elf [...]
#
# Exits 1 if any file is over budget. CDCR_SIZE (default arm-none-eabi-size)
# names the size tool.
set -euo pipefail

# 104 KiB since the payload's sag (payload_compliance.hpp: Newton steps with
# the moments' Jacobian and a small solve, and its inverse for IK) took the
# Cortex-M7 program 5.4 KB further, past 96 KiB; 108 KiB since IK's
# preference among redundant solutions (its null-space step, 4 KB); 112 KiB
# since the cable fit's residuals as GP inputs (6 KB); 120 KiB since three
# cables a segment (6.9 KB: every read-out of the cables through the
# segment's layout, a layout's weights derived from its angles, the cables
# block's checks); 128 KiB since CAN FD and a second bus (the FD messages'
# codecs, the pose and setpoints in FD frames, the drives' bus: the M7
# program 129,964 bytes).
readonly code_budget=$((128 * 1024))
readonly ram_budget=$((32 * 1024))
size_tool=${CDCR_SIZE:-arm-none-eabi-size}

if [[ $# -eq 0 ]]; then
  echo "usage: $0 FILE.elf..." >&2
  exit 2
fi
command -v "$size_tool" >/dev/null || { echo "$0: $size_tool not found (bash tools/install-deps.sh cross)" >&2; exit 2; }

over=0
printf '%-40s %8s %8s %8s %8s %8s %10s\n' "file" "code" "data" "bss" "stack" "RAM" "image"
for elf in "$@"; do
  [[ -f $elf ]] || { echo "$0: $elf: no such file" >&2; exit 2; }
  # `size -A` lists one section per line: name, size, address.
  read -r code data bss stack image < <("$size_tool" -A -d "$elf" | awk '
    $1 == ".vectors" || $1 == ".text" || $1 ~ /^\.ARM\./ || $1 == ".init_array" { code += $2 }
    $1 == ".data" { data += $2 }
    $1 == ".bss" { bss += $2 }
    $1 == ".stack" { stack += $2 }
    $1 == ".cdcr_model" { image += $2 }
    END { print code + 0, data + 0, bss + 0, stack + 0, image + 0 }')
  ram=$((data + bss + stack))
  # The build directory names the board: cross-m7/cdcr_mps2_firmware.elf.
  label="$(basename "$(dirname "$(dirname "$elf")")")/$(basename "$elf")"
  printf '%-40s %8d %8d %8d %8d %8d %10d\n' "$label" "$code" "$data" "$bss" "$stack" "$ram" "$image"
  if ((code > code_budget)); then
    echo "  over budget: code $code bytes > $code_budget" >&2
    over=1
  fi
  if ((ram > ram_budget)); then
    echo "  over budget: RAM $ram bytes > $ram_budget" >&2
    over=1
  fi
done
echo "budget: code <= $code_budget bytes, RAM (data + bss + stack) <= $ram_budget bytes"
exit $over
