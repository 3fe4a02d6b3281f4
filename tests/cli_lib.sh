# Shared by the command-line test scripts (cli_test.sh, attack_*_test.sh): the arguments, a temporary
# folder removed on exit, and the expectations. Usage, first line of a script: source cli_lib.sh "$@"
# with HAIRGEN SOURCE_DIR CASE as the script's arguments.
set -u
hairgen=$1 src=$2 case=$3
real="$src/../shared/testdata/real"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL ($case): $*"; exit 1; }
# A check that cannot run here is reported to ctest as skipped (SKIP_RETURN_CODE 77), never as passed.
skip() { echo "SKIP ($case): $*"; exit 77; }
expect_rc() { # expected-rc command...
  local want=$1; shift
  "$@" >"$tmp/out" 2>"$tmp/err"; local rc=$?
  [ "$rc" -eq "$want" ] || { cat "$tmp/out" "$tmp/err"; fail "'$*' exited $rc, expected $want"; }
}
expect_err() { # text the last expect_rc's stderr must hold
  grep -qF -- "$1" "$tmp/err" || fail "stderr lacks '$1': $(cat "$tmp/err")"
}
