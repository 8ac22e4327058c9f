# SPDX-License-Identifier: BSD-3-Clause
# The checks of the command-line tests, sourced by them: a temporary folder
# $work, counters $passed and $failed, and
#   expect_fail <description> <stderr substring> -- command...
#     a non-zero exit (not a timeout of $timeout_s s) and an error of one
#     line (CLI11 adds a second, "Run with --help") shorter than $max_length;
#   expect_ok <description> <stdout substring> -- command...
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
passed=0
failed=0
timeout_s=${timeout_s:-600}
max_length=${max_length:-1000}

expect_fail() {
  local description=$1 needle=$2
  shift 3
  timeout "$timeout_s" "$@" >"$work/out" 2>"$work/err"
  local status=$?
  local lines longest
  lines=$(wc -l <"$work/err")
  longest=$(awk '{ if (length($0) > n) n = length($0) } END { print n + 0 }' "$work/err")
  if [ "$status" -ne 0 ] && [ "$status" -ne 124 ] && grep -q -- "$needle" "$work/err" && [ "$lines" -le 2 ] &&
     [ "$longest" -lt "$max_length" ]; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL: $description (exit $status, $lines stderr lines, longest $longest)"; head -c 600 "$work/err"
  fi
}

expect_same() {
  local description=$1 a=$2 b=$3
  if cmp -s "$a" "$b"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL: $description: $a and $b differ"
  fi
}

expect_ok() {
  local description=$1 needle=$2
  shift 3
  if timeout "$timeout_s" "$@" >"$work/out" 2>"$work/err" && grep -q -- "$needle" "$work/out"; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL: $description"; cat "$work/out" "$work/err"
  fi
}
