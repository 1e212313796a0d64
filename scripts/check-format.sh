#!/usr/bin/env bash
# Checks that every tracked C++ and CUDA source is formatted as .clang-format says (Debian 12's clang-format 14).
#   check-format.sh          lists the files clang-format would change and exits 1 if there is any
#   check-format.sh --fix    formats them in place
# Exits 77 (ctest: skipped) with the reason when clang-format or git is missing or this is no git checkout.
# CLANG_FORMAT names another binary; other major versions may format some lines differently.
set -euo pipefail
cd "$(dirname "$0")/.."

clang_format=${CLANG_FORMAT:-clang-format}
if ! command -v "$clang_format" > /dev/null; then
  echo "check-format: skipped: $clang_format not found (Debian: apt install clang-format; scripts/install-deps.sh)"
  exit 77
fi
if ! command -v git > /dev/null || ! git rev-parse --is-inside-work-tree > /dev/null 2>&1; then
  echo "check-format: skipped: the tracked files come from git, and this is no git checkout"
  exit 77
fi

mapfile -d '' files < <(git ls-files -z -- '*.c' '*.cc' '*.cpp' '*.cxx' '*.h' '*.hh' '*.hpp' '*.hxx' '*.cu' '*.cuh')
if ((${#files[@]} == 0)); then
  echo "check-format: no C++ or CUDA sources tracked"
  exit 0
fi
version=$("$clang_format" --version)
case "${1:-}" in
  --fix)
    printf '%s\0' "${files[@]}" | xargs -0 -n 50 "$clang_format" -i --style=file
    echo "check-format: formatted ${#files[@]} files with $version"
    exit 0
    ;;
  "") ;;
  *) echo "check-format: unknown option '$1' (--fix)" >&2; exit 2 ;;
esac

# One clang-format process for all the files (one per file takes minutes on a loaded machine); its first
# complaint per file names the file.
log=$(printf '%s\0' "${files[@]}" |
  xargs -0 "$clang_format" --dry-run -Werror --ferror-limit=1 --style=file 2>&1) && status=0 || status=$?
mapfile -t unformatted < <(grep -oE '^[^:]+:[0-9]+:[0-9]+: (error|warning): code should be clang-formatted' <<< "$log" |
  cut -d: -f1 | sort -u)
if ((${#unformatted[@]} > 0)); then
  printf '%s\n' "${unformatted[@]}"
  echo "check-format: ${#unformatted[@]} of ${#files[@]} files are not formatted as .clang-format says ($version);" \
    "see the changes with: clang-format --dry-run FILE; fix them with: scripts/check-format.sh --fix"
  exit 1
fi
if ((status != 0)); then
  echo "$log"
  echo "check-format: $clang_format failed (exit $status) ($version)"
  exit 1
fi
echo "check-format: ${#files[@]} files formatted ($version)"
