#!/bin/sh
# view.dependencies: Node.js, and the view's reference clients
# (tools/view/clients) installed from their lock file.
#   check_dependencies.sh <node> <tools/view/clients>
group=view install_group=view
. "$(dirname "$0")/../../support/missing_dependency.sh"

require_program node "$1"
"$1" -e "
  const lock = require('$2/package-lock.json').packages;
  for (const [path, entry] of Object.entries(lock))
    if (path && require('$2/' + path + '/package.json').version !== entry.version) process.exit(1);
  for (const name of ['@foxglove/ws-protocol', '@mcap/core', '@foxglove/schemas', 'ws', 'ajv']) require('$2/node_modules/' + name);" \
  2>/dev/null || missing "the npm packages in $2 are not those of its package-lock.json, or one does not load"
echo "view: node $("$1" --version) with @mcap/core $("$1" -p "require('$2/node_modules/@mcap/core/package.json').version") and @foxglove/ws-protocol $("$1" -p "require('$2/node_modules/@foxglove/ws-protocol/package.json').version") present"
