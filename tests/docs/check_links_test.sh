#!/usr/bin/env bash
# check_links.sh finds what it is for: a scratch tree (no git) with good, fenced and three bad
# references must give exactly the three problems and exit 1. Usage: check_links_test.sh SCRIPT
set -euo pipefail
script=$1
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$scratch/docs" "$scratch/src"
echo "# Guide" > "$scratch/docs/guide.md"
printf 'docs/guide.md is here; docs/gone.md is not\n' > "$scratch/src/a.cc"
printf '[ok](guide.md) [bad](missing.md)\n```\n[skipped](fenced.md)\n```\nsee ../shared/docs\n' \
  > "$scratch/docs/page.md"
printf 'docs/binary.md\0' > "$scratch/src/blob.bin"  # binary: not read
status=0
out=$(bash "$script" "$scratch" 2>&1) || status=$?
expected="docs/page.md:5: points outside the repository: '../shared'
docs/page.md:1: link target missing.md does not resolve
src/a.cc:1: docs/gone.md does not exist
check_links: 3 problem(s)"
sorted=$(sort <<< "$out")
if [[ $status -ne 1 || $sorted != "$(sort <<< "$expected")" ]]; then
  echo "exit $status, output:"
  echo "$out"
  exit 1
fi
echo "check_links found the 3 planted problems"
