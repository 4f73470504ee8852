# tap.sh -- sourced by the shell tests: TAP helpers.
n=0; failed=0
ok() { # ok <status> <name>
  n=$((n + 1))
  if [ "$1" = 0 ]; then echo "ok $n - $2"; else echo "not ok $n - $2"; failed=$((failed + 1)); fi
}
is() { # is <got> <want> <name>
  if [ "$1" = "$2" ]; then ok 0 "$3"; else ok 1 "$3"; printf '#   got:  %s\n#   want: %s\n' "$1" "$2" | sed 's/^/# /'; fi
}
like() { # like <text> <grep -E pattern> <name>
  if printf '%s\n' "$1" | grep -Eq -- "$2"; then ok 0 "$3"; else ok 1 "$3"; printf '%s\n' "$1" | head -5 | sed 's/^/#   /'; fi
}
skip() { n=$((n + 1)); echo "ok $n # SKIP $1"; }
done_testing() { echo "1..$n"; [ "$failed" = 0 ]; exit $?; }
