#!/usr/bin/env bash
# check_links.sh finds what it is for: a scratch tree (no git) with good, fenced and three bad
# references must give exactly the three problems and exit 1. Usage: check_links_test.sh SCRIPT
# (The planted names are assembled from pieces, so that this file does not trip docs_links.)
set -euo pipefail
script=$1
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
d=docs
outside="../sha""red"
mkdir -p "$scratch/$d" "$scratch/src"
echo "# Guide" > "$scratch/$d/guide.md"
printf '%s is here; %s is not\n' "$d/guide.md" "$d/gone.md" > "$scratch/src/a.cc"
printf '[ok](guide.md) [bad](missing.md)\n```\n[skipped](fenced.md)\n```\nsee %s\n' \
  "$outside/$d" > "$scratch/$d/page.md"
printf '%s\0' "$d/binary.md" > "$scratch/src/blob.bin"  # binary: not read
status=0
out=$(bash "$script" "$scratch" 2>&1) || status=$?
expected="$d/page.md:5: points outside the repository: '$outside'
$d/page.md:1: link target missing.md does not resolve
src/a.cc:1: $d/gone.md does not exist
check_links: 3 problem(s)"
if [[ $status -ne 1 || $(sort <<< "$out") != "$(sort <<< "$expected")" ]]; then
  echo "exit $status, output:"
  echo "$out"
  exit 1
fi
echo "check_links found the 3 planted problems"
