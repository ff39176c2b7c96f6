# SPDX-License-Identifier: MIT
# Shared by the sweep test scripts (sourced after they set `work`): a fresh WORK_DIR, and fail(),
# which prints the message and every log of WORK_DIR, then exits 1.
fail() {
  echo "FAIL: $*" >&2
  for f in "$work"/*.log; do [ -f "$f" ] && { echo "--- $f" >&2; cat "$f" >&2; }; done
  exit 1
}
rm -rf "$work"
mkdir -p "$work"
