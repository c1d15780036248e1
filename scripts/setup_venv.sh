#!/usr/bin/env bash
# Creates (or reuses) the Python virtual environment with the independent test peers, and prints
# its interpreter's path on the last line. Location: $TC_VENV, default ~/.cache/thickness_collision/venv.
set -euo pipefail
venv="${TC_VENV:-$HOME/.cache/thickness_collision/venv}"
# Pinned peers (see ../shared/design.md, "Real peers for tests").
packages=(numpy "coal==3.0.3" "example-robot-data==6.0.0" "yourdfpy==0.0.60")
stamp="$venv/.tc-packages"
want="${packages[*]}"
if [ -x "$venv/bin/python" ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
    echo "reusing $venv" >&2
else
    python3 -m venv "$venv"
    "$venv/bin/python" -m pip install --quiet --upgrade pip >&2
    "$venv/bin/python" -m pip install --quiet "${packages[@]}" >&2
    echo "$want" > "$stamp"
fi
echo "$venv/bin/python"
