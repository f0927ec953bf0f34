#!/usr/bin/env bash
# Checks that the documentation is self-contained. Usage: check_links.sh SOURCE_DIR
#   (a) every `docs/<name>.md` named in a tracked file exists (paths from the repository root);
#   (b) every relative Markdown link `[text](path)` or `[label]: path` of a *.md file resolves,
#       from the page's own folder (http:, https:, mailto: and #anchors are not checked; the
#       #fragment of a path is dropped; fenced code blocks are skipped);
#   (c) nothing points at the project's material outside the repository (the parent folder's
#       shared/ tree: its docs and seeds).
# Prints one line per problem, `file:line: what`, and exits 1 if there is any.
# Files: `git ls-files` (tracked and untracked, not ignored) in a git checkout, else every file
# under SOURCE_DIR except .git, build*/ folders and the run results in results/.
set -euo pipefail

root=${1:?usage: check_links.sh SOURCE_DIR}
cd "$root"

files=()
if git rev-parse --is-inside-work-tree >/dev/null 2>&1 &&
   [[ $(git rev-parse --show-toplevel) -ef . ]]; then
  while IFS= read -r -d '' f; do [[ -f $f ]] && files+=("$f"); done \
    < <(git ls-files -z --cached --others --exclude-standard)
else
  while IFS= read -r -d '' f; do files+=("${f#./}"); done \
    < <(find . \( -name .git -o \( -type d -name 'build*' \) \
                  -o \( -path './results/*' ! -path ./results/README.md \) \) -prune \
             -o -type f -print0)
fi

problems=0
report() {  # file line message
  echo "$1:$2: $3"
  problems=$((problems + 1))
}

# (c) Written so that this script does not match itself.
outside='\.\./shared|shared/(docs|seeds)'

# (a) and (c): one grep over every text file (-I skips binary ones), file:line:match per hit.
# (a) docs/<name>.md, not as the tail of a longer path (tests/docs/x.md, ../docs/x.md).
while IFS= read -r hit; do
  f=${hit%%:*} rest=${hit#*:}
  line=${rest%%:*} match=${rest#*:}
  ref=docs/${match##*docs/}
  [[ -f $ref ]] || report "$f" "$line" "$ref does not exist"
done < <(printf '%s\0' "${files[@]}" |
         xargs -0 grep -HInoE '(^|[^A-Za-z0-9_./-])docs/[A-Za-z0-9_.-]+\.md' -- || true)
# (c)
while IFS= read -r hit; do
  f=${hit%%:*} rest=${hit#*:}
  report "$f" "${rest%%:*}" "points outside the repository: '${rest#*:}'"
done < <(printf '%s\0' "${files[@]}" | xargs -0 grep -HInoE "$outside" -- || true)

for f in "${files[@]}"; do
  # (b) Markdown pages only.
  [[ $f == *.md ]] || continue
  dir=$(dirname "$f")
  while IFS=$'\t' read -r line target; do
    target=${target#<}
    target=${target%>}
    case $target in
      http://* | https://* | mailto:* | '#'* | '') continue ;;
    esac
    path=${target%%#*}
    [[ -e $dir/$path ]] || report "$f" "$line" "link target $target does not resolve"
  done < <(awk '
      /^[ \t]*(```|~~~)/ { fenced = !fenced; next }
      fenced { next }
      {
        rest = $0
        while (match(rest, /\]\([^) \t]+([ \t]+"[^"]*")?\)/)) {
          link = substr(rest, RSTART + 2, RLENGTH - 3)
          sub(/[ \t]+".*$/, "", link)
          print NR "\t" link
          rest = substr(rest, RSTART + RLENGTH)
        }
        if (match($0, /^[ \t]*\[[^]]+\]:[ \t]+[^ \t]+/)) {
          link = $0
          sub(/^[ \t]*\[[^]]+\]:[ \t]+/, "", link)
          sub(/[ \t].*$/, "", link)
          print NR "\t" link
        }
      }' "$f")
done

if ((problems)); then
  echo "check_links: $problems problem(s)" >&2
  exit 1
fi
echo "check_links: ${#files[@]} files, no broken documentation reference"
