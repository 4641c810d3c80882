# Shared by the end-to-end CLI test scripts (sourced, after bin= and src=):
# a scratch folder that is removed on exit, pass/fail counters, and two checks.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
failures=0
passes=0
check() {  # check "what" command...
  local what=$1; shift
  if "$@"; then passes=$((passes + 1)); else echo "FAILED: $what"; failures=$((failures + 1)); fi
}
expect_error() {  # expect_error "what" exit_code "message substring" command...
  local what=$1 code=$2 text=$3; shift 3
  "$@" >out.txt 2>err.txt
  local rc=$?
  if [[ $rc -eq $code ]] && grep -qF -- "$text" err.txt; then passes=$((passes + 1)); else
    echo "FAILED: $what (exit $rc, stderr: $(head -20 err.txt))"; failures=$((failures + 1)); fi
}
