#!/usr/bin/env bash
# smallpt's scene (scenes/smallpt.json) against smallpt itself: Kevin
# Beason's 99-line path tracer, built here from its public source with two
# changes, so that its image is linear HDR: each subpixel's radiance is not
# clamped to 1 before the average, and the image is written as PFM.  Prints
# the relative RMS difference per pixel and over 4 x 4 blocks, and the image
# mean's difference, for:
#   - zonetrace (its box filter over each pixel) against smallpt;
#   - zonetrace with smallpt's pixel filter against smallpt: smallpt
#     averages 2 x 2 subpixels, each sampled with a tent of half a pixel's
#     half-width around the subpixel's centre, which reaches a quarter pixel
#     past the pixel and weighs its centre most;
#   - two smallpt images of different seeds (its own noise, twice one
#     image's variance).
# zonetrace renders once, at 4 times the size plus a margin of one fine
# pixel, at 1/16 of the samples; bench/support/smallpt_filter.py makes both
# of its images from that one: the mean of each pixel's 4 x 4 fine pixels
# (the box filter), and smallpt's filter.  It renders to depth 1000:
# smallpt has no depth limit, only its Russian roulette (the default of 16
# loses 0.07% of this room's light).
#
#   bench/smallpt_compare.sh SMALLPT_CPP [WIDTH HEIGHT SPP]
#
# SMALLPT_CPP is smallpt.cpp as published (www.kevinbeason.com/smallpt);
# defaults 256 x 192 at 8192 spp (about 15 minutes on 2 cores: 5 for each
# smallpt image, 4 for zonetrace's).  SPP a multiple of 16.  ZONETRACE
# names another zonetrace binary (default build/app/zonetrace).
set -euo pipefail
src=${1:?usage: smallpt_compare.sh SMALLPT_CPP [WIDTH HEIGHT SPP]}
w=${2:-256}; h=${3:-192}; spp=${4:-8192}
here=$(cd "$(dirname "$0")" && pwd)
zt=${ZONETRACE:-$here/../build/app/zonetrace}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The changes: size, samples and seed from the command line, no clamp, PFM.
python3 - "$src" "$tmp/smallpt_hdr.cpp" <<'PY'
import re, sys
s = open(sys.argv[1]).read()
def sub(pat, rep):
    global s
    s2, n = re.subn(pat, lambda m: rep, s, flags=re.S)
    if n != 1:
        sys.exit("smallpt_compare: the source does not look like smallpt.cpp (%s)" % pat)
    s = s2
sub(r"int w=1024, h=768, samps = [^;]*;",
    "int w=atoi(argv[1]), h=atoi(argv[2]), samps=atoi(argv[3])/4;")
sub(r"Xi\[3\]=\{0,0,(?:\(unsigned short\))?\(?y\*y\*y\)?\}", "Xi[3]={0,(unsigned short)atoi(argv[5]),(unsigned short)(y*y*y)}")
sub(r"c\[i\] = c\[i\] \+ Vec\(clamp\(r\.x\),clamp\(r\.y\),clamp\(r\.z\)\)\*\.25;",
    "c[i] = c[i] + r*.25;")
sub(r"FILE \*f = fopen\(\"image\.ppm\", \"w\"\);.*\n\}\s*$",
    "FILE *f = fopen(argv[4], \"wb\"); fprintf(f, \"PF\\n%d %d\\n-1.0\\n\", w, h);\n"
    "  for (int y=h-1; y>=0; y--) for (int x=0; x<w; x++) {\n"
    "    float v[3] = {(float)c[y*w+x].x, (float)c[y*w+x].y, (float)c[y*w+x].z};\n"
    "    fwrite(v, sizeof v, 1, f); }\n  fclose(f);\n}\n")
open(sys.argv[2], "w").write(s)
PY
g++ -O3 -fopenmp "$tmp/smallpt_hdr.cpp" -o "$tmp/smallpt"
"$tmp/smallpt" "$w" "$h" "$spp" "$tmp/smallpt_a.pfm" 0 2>/dev/null
"$tmp/smallpt" "$w" "$h" "$spp" "$tmp/smallpt_b.pfm" 1 2>/dev/null
# zonetrace at 4 times the size plus a fine pixel's margin, 1/16 the samples.
scene="$here/../scenes/smallpt.json"
filt="$here/support/smallpt_filter.py"
python3 "$filt" scene "$scene" "$tmp/smallpt_fine.json" "$w" "$h"
"$zt" render "$tmp/smallpt_fine.json" --size "$((4 * w + 2))x$((4 * h + 2))" \
  --spp "$(( spp / 16 > 0 ? spp / 16 : 1 ))" --depth 1000 -o "$tmp/zt_fine.pfm" -q
python3 "$filt" box "$tmp/zt_fine.pfm" "$tmp/zt.pfm"
python3 "$filt" filter "$tmp/zt_fine.pfm" "$tmp/zt_filtered.pfm"
for what in "zonetrace against smallpt:zt.pfm" \
            "zonetrace, smallpt's filter:zt_filtered.pfm" \
            "smallpt against itself:smallpt_b.pfm"; do
  label=${what%%:*}; img=${what#*:}
  out=$("$zt" compare "$tmp/$img" "$tmp/smallpt_a.pfm")
  px=$(sed -n 's/^rel_rmse //p' <<<"$out")
  blk=$("$zt" compare "$tmp/$img" "$tmp/smallpt_a.pfm" --block 4 | sed -n 's/^rel_rmse //p')
  mean=$(awk '/^mean_image/ {a = $2 + $3 + $4} /^mean_reference/ {b = $2 + $3 + $4}
              END {printf "%+.2f%%", 100 * (a / b - 1)}' <<<"$out")
  printf '%-28s per pixel %s, 4x4 blocks %s, mean %s\n' "$label" "$px" "$blk" "$mean"
done
