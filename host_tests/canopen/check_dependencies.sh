#!/bin/sh
# canopen.dependencies: Node.js, and the npm packages of the simulated CiA 402
# drives (tools/sim/cia402) installed from their lock file, the canopen stack
# loading with its native part built.
#   check_dependencies.sh <node> <tools/sim/cia402>
group=canopen install_group=canopen
. "$(dirname "$0")/../support/missing_dependency.sh"

require_program node "$1"
[ -f "$2/node_modules/canopen/package.json" ] || missing "the npm package canopen is not installed in $2"
"$1" -e "
  const lock = require('$2/package-lock.json').packages;
  for (const [path, entry] of Object.entries(lock))
    if (path && require('$2/' + path + '/package.json').version !== entry.version) process.exit(1);
  require('$2/node_modules/canopen');" 2>/dev/null ||
  missing "the npm packages in $2 are not those of its package-lock.json, or canopen does not load"
echo "canopen: node $("$1" --version) with canopen $("$1" -p "require('$2/node_modules/canopen/package.json').version") present"
