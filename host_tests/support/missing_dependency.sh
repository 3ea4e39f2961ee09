# Sourced by the <group>/check_dependencies.sh scripts, which run as the
# <group>.dependencies test: every other test of the group requires it (a
# ctest fixture), so a group whose tools are missing fails loudly, with one
# line naming what is missing and the install-deps group that brings it,
# instead of dropping out of ctest. Set `group` and `install_group` first.

# missing <what>: the one line, and the test fails.
missing() {
  echo "$group tests cannot run: $1; install with: bash tools/install-deps.sh $install_group (then re-run cmake)"
  exit 1
}

# require_program <name> <path cmake found, or *-NOTFOUND>
require_program() {
  case $2 in
    "" | *-NOTFOUND) missing "$1 not found" ;;
  esac
  [ -x "$2" ] || missing "$1 not found at $2"
}
