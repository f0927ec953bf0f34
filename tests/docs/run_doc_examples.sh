#!/usr/bin/env bash
# Runs every ```sh block of one Markdown page, in order, in a scratch folder with the repository's
# scenarios/ and the built mbid on the PATH. Usage: run_doc_examples.sh PAGE.md MBID SOURCE_DIR
set -euo pipefail
page=$1 mbid=$2 source_dir=$3
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
ln -s "$source_dir/scenarios" "$scratch/scenarios"
mkdir -p "$scratch/bin" && ln -s "$mbid" "$scratch/bin/mbid"
export PATH="$scratch/bin:$PATH"
# The blocks, one script: a later block may use what an earlier one made.
awk '/^```sh$/ { inside = 1; print "echo \"--- example at line " NR "\""; next }
     /^```/ { inside = 0; next }
     inside' "$page" > "$scratch/examples.sh"
blocks=$(grep -c '^echo "--- example' "$scratch/examples.sh" || true)
if [[ $blocks -eq 0 ]]; then
  echo "no sh example in $page" >&2
  exit 1
fi
cd "$scratch"
bash -euo pipefail examples.sh
echo "$blocks example blocks of $page ran"
