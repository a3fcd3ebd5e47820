#!/usr/bin/env bash
# The tree follows .clang-format: every C++ file under the layer folders, perf/ and tests/ is left unchanged by
# clang-format. Formatting differs between clang-format versions, so only the version .clang-format was written
# for (14, Debian 12's) decides; another version skips the test (exit 77).
#   check_format.sh <clang-format> <source root>
set -euo pipefail
clang_format=$1
root=$2
version=$("$clang_format" --version | sed -n 's/.*version \([0-9]*\)\..*/\1/p')
if [ "$version" != 14 ]; then
  echo "skipped: clang-format $version; .clang-format is checked with version 14"
  exit 77
fi
cd "$root"
mapfile -t files < <(find core models kernels engine drivers perf tests -name '*.hpp' -o -name '*.cpp' | sort)
bad=()
for f in "${files[@]}"; do
  "$clang_format" --dry-run --Werror "$f" > /dev/null 2>&1 || bad+=("$f")
done
if [ ${#bad[@]} -gt 0 ]; then
  echo "not formatted (run: clang-format -i ${bad[*]}):" >&2
  for f in "${bad[@]}"; do "$clang_format" --dry-run "$f" 2>&1 | head -n 3 >&2; done
  exit 1
fi
echo "ok: ${#files[@]} files follow .clang-format"
