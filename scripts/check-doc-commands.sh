#!/usr/bin/env bash
# Checks that README.md, CHANGELOG.md and docs/*.md still describe the
# repository as it is:
#
#  (a) a code block right after a line `<!-- file: PATH -->` must equal the
#      file PATH (relative to the repository root), byte for byte;
#  (b) a code block right after a line `<!-- check -->` is run with bash
#      (errexit, nounset, pipefail) in a fresh temporary directory, with every
#      `build/examples/` replaced by the directory of the built programs; a
#      non-zero exit fails the check. Only commands that need no real data
#      are marked so;
#  (c) a code block right after a line `<!-- prints: COMMAND -->` must equal
#      what COMMAND prints on standard output (run with bash as in (b), in a
#      fresh temporary directory, `build/examples/` replaced the same way),
#      byte for byte: the output blocks of the programs' built-in runs cannot
#      drift from what the programs print. Only fast, data-free commands are
#      marked so;
#  (d) every relative link `[text](target)` outside code must name an
#      existing file or directory (anchors are not checked).
#
# Usage: scripts/check-doc-commands.sh [PROGRAM_DIR]
#   PROGRAM_DIR  where the example programs were built (default:
#                build/examples of the checkout, the default preset's).
# Documents: README.md, CHANGELOG.md, docs/*.md and docs/*/*.md.
# Exit status: 0 when everything holds, 1 otherwise (each failure is named
# as document:line on stderr).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=${1:-$root/build/examples}
if ! bin=$(cd "$bin" 2>/dev/null && pwd); then
  echo "check-doc-commands: no program directory '${1:-$root/build/examples}' (build the examples first)" >&2
  exit 1
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

docs=("$root/README.md")
[[ -f $root/CHANGELOG.md ]] && docs+=("$root/CHANGELOG.md")
for f in "$root"/docs/*.md "$root"/docs/*/*.md; do [[ -f $f ]] && docs+=("$f"); done

failures=0
fail() {
  echo "check-doc-commands: $*" >&2
  failures=$((failures + 1))
}

# One pass per document: the marked blocks go to $work/block.<n>, and
# $work/index gets one tab-separated line per item:
#   file  <n> <path>   <doc>:<line>
#   check <n> -        <doc>:<line>
#   prints <n> <command> <doc>:<line>
#   link  -   <target> <doc>:<line>
#   error -   <text>   <doc>:<line>
n=0
: >"$work/index"
for doc in "${docs[@]}"; do
  rel=${doc#"$root"/}
  n=$(awk -v doc="$rel" -v dir="$work" -v n="$n" '
    function flush_marker(reason) {
      if (kind != "") printf "error\t-\ta <!-- %s --> marker %s\t%s:%d\n", kind, reason, doc, mline >> (dir "/index")
      kind = ""
    }
    BEGIN { kind = ""; infence = 0; out = "" }
    {
      line = $0
      sub(/\r$/, "", line)
      if (infence) {
        if (line ~ /^```[ \t]*$/) { infence = 0; if (out != "") close(out); out = ""; next }
        if (out != "") print line > out
        next
      }
      if (line ~ /^```/) {
        infence = 1
        if (kind != "") {
          n++
          out = dir "/block." n
          printf "" > out
          printf "%s\t%d\t%s\t%s:%d\n", kind, n, (kind == "check" ? "-" : arg), doc, mline >> (dir "/index")
          kind = ""
        }
        next
      }
      if (match(line, /^<!-- file: [^ ]+ -->[ \t]*$/)) {
        flush_marker("is not followed by a code block")
        kind = "file"; mline = NR
        arg = line; sub(/^<!-- file: /, "", arg); sub(/ -->[ \t]*$/, "", arg)
        next
      }
      if (match(line, /^<!-- prints: .+ -->[ \t]*$/)) {
        flush_marker("is not followed by a code block")
        kind = "prints"; mline = NR
        arg = line; sub(/^<!-- prints: /, "", arg); sub(/ -->[ \t]*$/, "", arg)
        next
      }
      if (line ~ /^<!-- check -->[ \t]*$/) {
        flush_marker("is not followed by a code block")
        kind = "check"; mline = NR
        next
      }
      if (kind != "" && line !~ /^[ \t]*$/) flush_marker("is not followed by a code block")
      # Links outside code: drop inline code spans first.
      text = line
      gsub(/`[^`]*`/, "", text)
      while (match(text, /\]\([^)]+\)/)) {
        target = substr(text, RSTART + 2, RLENGTH - 3)
        text = substr(text, RSTART + RLENGTH)
        sub(/[ \t]+"[^"]*"$/, "", target)
        if (target ~ /^[a-zA-Z][a-zA-Z0-9+.-]*:/ || target ~ /^#/) continue
        sub(/#.*$/, "", target)
        printf "link\t-\t%s\t%s:%d\n", target, doc, NR >> (dir "/index")
      }
    }
    END {
      flush_marker("is not followed by a code block")
      if (infence) printf "error\t-\tan unterminated code block\t%s:%d\n", doc, NR >> (dir "/index")
      print n
    }' "$doc")
done

files=0 checks=0 prints=0 links=0

# Runs a command block or a prints command ($1: the script file) with the
# programs of $bin; stdout to $2, stderr to $3. Fails when a program it names
# is not built.
run_block() {
  local script=$1 out=$2 err=$3 prog missing="" dir
  for prog in $(grep -o 'build/examples/[A-Za-z0-9_]*' "$script" | sort -u); do
    [[ -x $bin/${prog#build/examples/} ]] || missing+=" ${prog#build/examples/}"
  done
  if [[ -n $missing ]]; then
    echo "not built in $bin:$missing" >"$err"
    return 1
  fi
  dir=$(mktemp -d "$work/run.XXXXXX")
  sed "s#build/examples/#$bin/#g" "$script" >"$dir.sh"
  (cd "$dir" && timeout 600 bash -euo pipefail "$dir.sh") </dev/null >"$out" 2>"$err"
}
while IFS=$'\t' read -r -u 3 kind num arg where; do
  case $kind in
    error)
      fail "$where: $arg"
      ;;
    file)
      files=$((files + 1))
      if [[ ! -f $root/$arg ]]; then
        fail "$where: $arg does not exist"
      elif ! cmp -s "$work/block.$num" "$root/$arg"; then
        fail "$where: the code block differs from $arg:"
        diff -u "$root/$arg" "$work/block.$num" | sed -n '3,40p' >&2 || true
      fi
      ;;
    check)
      checks=$((checks + 1))
      if ! run_block "$work/block.$num" "$work/out.$num" "$work/err.$num"; then
        fail "$where: the command block failed:"
        sed 's/^/  | /' "$work/block.$num" >&2
        cat "$work/out.$num" "$work/err.$num" 2>/dev/null | tail -n 20 | sed 's/^/  > /' >&2
      fi
      ;;
    prints)
      prints=$((prints + 1))
      printf '%s\n' "$arg" >"$work/cmd.$num"
      if ! run_block "$work/cmd.$num" "$work/out.$num" "$work/err.$num"; then
        fail "$where: the command '$arg' failed:"
        tail -n 20 "$work/err.$num" | sed 's/^/  > /' >&2
      elif ! cmp -s "$work/block.$num" "$work/out.$num"; then
        fail "$where: the block differs from what '$arg' prints (- document, + program):"
        diff -u "$work/block.$num" "$work/out.$num" | sed -n '3,40p' >&2 || true
      fi
      ;;
    link)
      links=$((links + 1))
      doc=${where%:*}
      base=$(dirname "$root/$doc")
      [[ -e $base/$arg ]] || fail "$where: the link target $arg does not exist"
      ;;
  esac
done 3<"$work/index"

if ((failures > 0)); then
  echo "check-doc-commands: $failures failure(s)" >&2
  exit 1
fi
echo "check-doc-commands: ${#docs[@]} documents: $files file blocks equal their files," \
  "$checks command blocks ran, $prints output blocks equal what their commands print," \
  "$links relative links resolve"
