#!/bin/sh
# The system packages the tests need: Debian's Chromium, which the browser tests drive with Playwright
# (it brings ALSA's libasound too, which python-rtmidi, the live MIDI input, loads).
set -e
if command -v chromium >/dev/null 2>&1; then
    exit 0
fi
if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium
