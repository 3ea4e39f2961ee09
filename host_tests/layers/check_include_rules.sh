#!/usr/bin/env bash
# The layers' include rule. The project is built in layers,
#   model <- hal <- firmware <- tools/sim <- the rest of tools,
# and a file may include headers of its own layer and of the layers below it,
# never of one above: the model includes no HAL, firmware or tool header, the
# HAL no firmware or tool header, the firmware no tool header, and the
# simulated robot no other tool's. Beside the chain, two pairs keep apart:
# the trainer (tools/train) and the image writer (tools/export) include
# nothing of each other (what they share is tools/trained_model, and
# tools/pipeline uses both), and no test includes the cdcr program's files
# (tools/cdcr): a test reaches the command through its library (tools/cli)
# or by running it, and a firmware, model or bus test that needs a sender
# or a report uses the layer that has it.
#
# Within the HAL, the interfaces (hal/include) and each backend (hal/linux,
# hal/sim, ...) are layers of their own: the runtime is written against the
# interfaces only (hal/hal.hpp), so the model, the HAL's interfaces and the
# firmware include no backend's header, and a backend none of another's
# but the bare-metal code it builds on (hal/baremetal, under hal/cortexm and
# hal/zynqmp). What picks a backend may include it: a board (firmware/boards)
# or an example's board file (firmware/examples), the C API its callbacks'
# backend (hal/callbacks), the tools and the tests any.
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

# Sets `backend` to the HAL backend folder a path lies in (hal/linux, ...;
# empty: none).
backend_of() {
  backend=
  if [[ $1 == hal/*/* && $1 != hal/include/* ]]; then
    backend=${1#hal/}
    backend=hal/${backend%%/*}
  fi
}

# The backends `file` may include (besides its own): "any" or a list.
backends_allowed() {
  case $1 in
    hal/cortexm/* | hal/zynqmp/*) allowed=hal/baremetal ;;
    firmware/boards/* | firmware/examples/* | tools/*) allowed=any ;;
    firmware/include/cdcr/cdcr.h | firmware/src/c_api.cpp) allowed=hal/callbacks ;;
    *) allowed= ;;
  esac
}

source_files() {
  find "$@" -type f \( -name '*.hpp' -o -name '*.h' -o -name '*.cpp' -o -name '*.c' -o -name '*.inc' \) | LC_ALL=C sort
}
mapfile -t sources < <(source_files model hal firmware tools)
mapfile -t tests < <(source_files host_tests)
if ((${#sources[@]} == 0)); then
  echo "no sources found below $(pwd)"
  exit 1
fi

# Every tail of every source path ("cdcr/hal/can_bus.hpp", "hal/can_bus.hpp",
# "can_bus.hpp") names the layers of the files it can reach, and the tools'
# folders they lie in.
declare -A lowest_layer
declare -A tool_folders
declare -A tail_backends   # the backends a tail names, if it names only backends' files
declare -A tail_elsewhere  # set: the tail names a file outside every backend
for file in "${sources[@]}"; do
  layer_of "$file"
  backend_of "$file"
  tool_folder=
  if [[ $file == tools/*/* ]]; then
    tool_folder=${file#tools/}
    tool_folder=tools/${tool_folder%%/*}
  fi
  tail=$file
  while [[ $tail == */* ]]; do
    tail=${tail#*/}
    if [[ -z ${lowest_layer[$tail]:-} ]] || ((rank < lowest_layer[$tail])); then
      lowest_layer[$tail]=$rank
    fi
    if [[ -n $tool_folder && " ${tool_folders[$tail]:-} " != *" $tool_folder "* ]]; then
      tool_folders[$tail]="${tool_folders[$tail]:-} $tool_folder"
    fi
    if [[ -z $backend ]]; then
      tail_elsewhere[$tail]=1
    elif [[ " ${tail_backends[$tail]:-} " != *" $backend "* ]]; then
      tail_backends[$tail]="${tail_backends[$tail]:-} $backend"
    fi
  done
done

# Sets `reached` to the tools' folders an include can resolve to.
folders_reached() {
  local file=$1 included=$2 beside=${1%/*}/$2
  if [[ -f $beside ]]; then
    beside=$(realpath -m --relative-to=. "$beside")
    reached=
    if [[ $beside == tools/*/* ]]; then
      reached=${beside#tools/}
      reached=tools/${reached%%/*}
    fi
  else
    reached=${tool_folders[$included]:-}
  fi
}

# "A B": files under A include nothing under B.
kept_apart=("tools/train tools/export" "tools/export tools/train" "host_tests tools/cdcr")

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
  folders_reached "$file" "$included"
  for pair in "${kept_apart[@]}"; do
    from=${pair% *}
    to=${pair#* }
    if [[ $file == "$from"/* && " $reached " == *" $to "* ]]; then
      echo "$file:$line_number: includes $included, from $to, which $from keeps apart from"
      violations=$((violations + 1))
    fi
  done
  [[ $file == host_tests/* ]] && continue
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
  # The backends the include can resolve to.
  if [[ -f $beside ]]; then
    backend_of "$beside"
    reached_backends=$backend
  elif [[ -z ${tail_elsewhere[$included]:-} ]]; then
    reached_backends=${tail_backends[$included]:-}
  else
    reached_backends=
  fi
  if [[ -n $reached_backends ]]; then
    backend_of "$file"
    backends_allowed "$file"
    for reached_backend in $reached_backends; do
      [[ $reached_backend == "$backend" || $allowed == any || " $allowed " == *" $reached_backend "* ]] && continue
      echo "$file:$line_number: includes $included, a header of the HAL backend $reached_backend, from ${backend:-${layer_names[own]}}"
      violations=$((violations + 1))
    done
  fi
done < <(grep -nH -E '^[[:space:]]*#[[:space:]]*include' "${sources[@]}" "${tests[@]}")

if ((violations > 0)); then
  echo "$violations include(s) go up the chain model <- hal <- firmware <- tools/sim <- tools, reach a HAL backend from outside it, or join what is kept apart"
  exit 1
fi
echo "$((${#sources[@]} + ${#tests[@]})) files, $checked includes: none goes up the chain model <- hal <- firmware <- tools/sim <- tools, none reaches a HAL backend but from what picks it, tools/train and tools/export include nothing of each other, no test includes tools/cdcr"
