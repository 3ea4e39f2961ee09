#!/usr/bin/env bash
# The layers' include rule. The project is built in layers,
#   model <- hal <- firmware <- tools/sim <- the rest of tools,
# and a file may include headers of its own layer and of the layers below it,
# never of one above: the model includes no HAL, firmware or tool header, the
# HAL no firmware or tool header, the firmware no tool header, and the
# simulated robot no other tool's.
#
# Every #include of every source file under the four folders is resolved the
# way the compiler would find it in this tree (next to the including file, or
# as the tail of a path below a layer); a header found nowhere in the tree (a
# system or generated header) is not a layer's. Prints every include that
# goes up the chain and fails if there is one.
#
# Usage: check_include_rules.sh <source dir>
set -euo pipefail
cd "${1:?usage: check_include_rules.sh <source dir>}"

layer_names=(model hal firmware tools/sim tools)

# Sets `rank` to the layer of a path relative to the source dir (-1: none).
layer_of() {
  case $1 in
    model/*) rank=0 ;;
    hal/*) rank=1 ;;
    firmware/*) rank=2 ;;
    tools/sim/*) rank=3 ;;
    tools/*) rank=4 ;;
    *) rank=-1 ;;
  esac
}

mapfile -t sources < <(find model hal firmware tools -type f \
  \( -name '*.hpp' -o -name '*.h' -o -name '*.cpp' -o -name '*.c' -o -name '*.inc' \) | LC_ALL=C sort)
if ((${#sources[@]} == 0)); then
  echo "no sources found below $(pwd)"
  exit 1
fi

# Every tail of every source path ("cdcr/hal/can_bus.hpp", "hal/can_bus.hpp",
# "can_bus.hpp") names the layers of the files it can reach.
declare -A lowest_layer
for file in "${sources[@]}"; do
  layer_of "$file"
  tail=$file
  while [[ $tail == */* ]]; do
    tail=${tail#*/}
    if [[ -z ${lowest_layer[$tail]:-} ]] || ((rank < lowest_layer[$tail])); then
      lowest_layer[$tail]=$rank
    fi
  done
done

violations=0
checked=0
while IFS= read -r match; do
  file=${match%%:*}
  rest=${match#*:}
  line_number=${rest%%:*}
  line=${rest#*:}
  [[ $line =~ ^[[:space:]]*#[[:space:]]*include[[:space:]]*[\"\<]([^\"\>]+)[\"\>] ]] || continue
  included=${BASH_REMATCH[1]}
  checked=$((checked + 1))
  layer_of "$file"
  own=$rank
  beside=${file%/*}/$included
  if [[ -f $beside ]]; then
    [[ $included == *..* ]] && beside=$(realpath -m --relative-to=. "$beside")
    layer_of "$beside"
    target=$rank
  elif [[ -n ${lowest_layer[$included]:-} ]]; then
    target=${lowest_layer[$included]}
  else
    continue
  fi
  if ((target > own)); then
    echo "$file:$line_number: includes $included, a ${layer_names[target]} header, from ${layer_names[own]}"
    violations=$((violations + 1))
  fi
done < <(grep -nH -E '^[[:space:]]*#[[:space:]]*include' "${sources[@]}")

if ((violations > 0)); then
  echo "$violations include(s) go up the chain model <- hal <- firmware <- tools/sim <- tools"
  exit 1
fi
echo "${#sources[@]} files, $checked includes: none goes up the chain model <- hal <- firmware <- tools/sim <- tools"
