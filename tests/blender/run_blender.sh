#!/usr/bin/env bash
# Runs a test script inside headless Blender with the staged add-on: run_blender.sh SCRIPT ADDON_STAGE_DIR.
# Exit 77 (skipped) when Blender is not installed; otherwise Blender's exit code (1 when the script fails).
set -u
script=$1
stage=$2
if ! command -v blender >/dev/null 2>&1; then
    echo "SKIP: blender is not installed (scripts/setup.sh installs Debian's blender)"
    exit 77
fi
# Blender's own thread count follows the machine; its user configuration is kept out of the way.
export BLENDER_USER_CONFIG BLENDER_USER_SCRIPTS
BLENDER_USER_CONFIG=$(mktemp -d)
BLENDER_USER_SCRIPTS=$BLENDER_USER_CONFIG
trap 'rm -rf "$BLENDER_USER_CONFIG"' EXIT
blender -b --factory-startup --python-exit-code 1 --python "$script" -- "$stage"
