#!/bin/sh
# Command-line contract tests for the vdag tool. Usage: tests/cli.sh VDAG
set -u
VDAG=${1:-build/vdag}
pass=0
fail=0
ok() { pass=$((pass + 1)); }
ko() { fail=$((fail + 1)); echo "  FAIL: $*" >&2; }
"$VDAG" --help >/dev/null 2>&1 && ok || ko "vdag --help"
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
