#!/usr/bin/env bash
# Golden outputs for refactors: renders a fixed set of stills, a short video,
# a .glb and an ARKit CSV through the CLI (whose commands and flags are the
# stable interface), then prints one sha256 per file. Run it before and after
# a change that should not alter outputs and diff the two listings:
#   bash scripts/golden_outputs.sh /tmp/before; ...; bash scripts/golden_outputs.sh /tmp/after
#   python scripts/compare_images.py /tmp/before /tmp/after
set -euo pipefail
out=${1:?usage: golden_outputs.sh OUTDIR}
mkdir -p "$out"
r() { facsim render "$@" --size 256 >/dev/null; }
r "1+2+5B+26" -o "$out/r01.png" --character kwame --view three-quarter-left
r "6+12" -o "$out/r02.png" --character amara
r "R12A+R14A" -o "$out/r03.png" --character ava --view three-quarter-right --background transparent
r "4+6" -o "$out/r04.png" --engine muscle --character george
r "1+2" -o "$out/r05.png" --engine muscle --character mei --view profile-left
r "51+61" -o "$out/r06.png" --yaw 20 --pitch 5 --projection orthographic --character hiro
r "9+10+25" -o "$out/r07.png" --character random:7
r "12@70%+26" -o "$out/r08.png" --engine muscle --character kofi --antialias fxaa
r --emotion fear --intensity 50% --table emfacs -o "$out/r09.png" --character emma
r --emotion sadness -o "$out/r10.png" --engine muscle --character margaret
r "53+64+43" -o "$out/r11.png" --character tunde --antialias 1
r "12C" -o "$out/r12.png" --intensities facshuman --character sofia --size 200x240
r --timeline examples/surprise_sequence.yaml --time 1.2 -o "$out/r13.png" --engine muscle
facsim emotion "6+12" -o "$out/v01" --onset 0.2 --apex 0.1 --offset 0.2 --fps 10 --size 128 --quiet --character liam >/dev/null
facsim animate examples/overlapping_aus.yaml -o "$out/v02" --fps 5 --size 96 --quiet --engine muscle >/dev/null
facsim emotion happiness -o "$out/v03.mp4" --onset 0.2 --apex 0.1 --offset 0.2 --fps 10 --size 128 --quiet >/dev/null
facsim export glb -o "$out/e01.glb" --character ava --timeline examples/overlapping_aus.yaml >/dev/null
facsim export arkit-csv examples/overlapping_aus.yaml -o "$out/e02.csv" >/dev/null
facsim export mesh "4+6" --engine muscle -o "$out/e03.ply" >/dev/null
facsim export notation examples/overlapping_aus.yaml -o "$out/e04.facs" >/dev/null
(cd "$out" && find . -type f | sort | xargs sha256sum)
