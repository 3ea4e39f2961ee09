#!/bin/sh
# browser.dependencies: the headless browser of the view's screenshot test.
#   browser_dependencies.sh <chromium>
group=browser install_group=browser
. "$(dirname "$0")/../../support/missing_dependency.sh"

require_program chromium "$1"
echo "browser: $("$1" --version 2>/dev/null) present"
