#!/usr/bin/env bash
# smallpt's scene (scenes/smallpt.json) against smallpt itself: Kevin
# Beason's 99-line path tracer, built here from its public source with two
# changes, so that its image is linear HDR: each subpixel's radiance is not
# clamped to 1 before the average, and the image is written as PFM.  Prints
# the relative RMS difference per pixel and over 4 x 4 blocks, and the same
# between two smallpt images of different seeds (its own noise).
#
#   bench/smallpt_compare.sh SMALLPT_CPP [WIDTH HEIGHT SPP]
#
# SMALLPT_CPP is smallpt.cpp as published (www.kevinbeason.com/smallpt);
# defaults 256 x 192 at 8192 spp (about 10 minutes on 2 cores).
set -euo pipefail
src=${1:?usage: smallpt_compare.sh SMALLPT_CPP [WIDTH HEIGHT SPP]}
w=${2:-256}; h=${3:-192}; spp=${4:-8192}
here=$(cd "$(dirname "$0")" && pwd)
zt="$here/../build/app/zonetrace"
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
"$zt" render "$here/../scenes/smallpt.json" --size "${w}x$h" --spp "$spp" -o "$tmp/zt.pfm" -q
for what in "zonetrace against smallpt:zt.pfm" "smallpt against itself:smallpt_b.pfm"; do
  label=${what%%:*}; img=${what#*:}
  px=$("$zt" compare "$tmp/$img" "$tmp/smallpt_a.pfm" | sed -n 's/^rel_rmse //p')
  blk=$("$zt" compare "$tmp/$img" "$tmp/smallpt_a.pfm" --block 4 | sed -n 's/^rel_rmse //p')
  printf '%-28s per pixel %s, 4x4 blocks %s\n' "$label" "$px" "$blk"
done
