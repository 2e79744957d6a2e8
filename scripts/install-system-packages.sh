#!/bin/sh
# The system packages the tests need, each installed only if it is missing:
# - Debian's Chromium, which the browser tests drive with Playwright (it brings ALSA's libasound too,
#   which python-rtmidi, the live MIDI input, loads);
# - FluidSynth and the General MIDI SoundFonts FluidR3_GM and TimGM6mb, which render a kit's hits through
#   real drum samples (drumstroke.render.soundfont; the recorded-drum corpus of the onset tests).
set -e
missing=""
command -v chromium >/dev/null 2>&1 || missing="$missing chromium"
command -v fluidsynth >/dev/null 2>&1 || missing="$missing fluidsynth"
[ -f /usr/share/sounds/sf2/FluidR3_GM.sf2 ] || missing="$missing fluid-soundfont-gm"
[ -f /usr/share/sounds/sf2/TimGM6mb.sf2 ] || missing="$missing timgm6mb-soundfont"
if [ -z "$missing" ]; then
    exit 0
fi
if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi
$SUDO apt-get update -qq
# shellcheck disable=SC2086  # one word per package
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing
