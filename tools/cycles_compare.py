#!/usr/bin/env python3
"""Compares two linear PFM images (a renderer against a reference), in plain Python.

    python3 tools/cycles_compare.py diff TEST.pfm REF.pfm [--block 4] [--mask LEVEL0.pfm]
                                    [--map OUT.ppm] [--worst N] [--rect X0 Y0 X1 Y1 ...]
    python3 tools/cycles_compare.py mean OUT.pfm A.pfm [B.pfm ...]

diff prints, over the pixels (or blocks) kept:
  means       the image mean of each channel in TEST and REF and their relative difference
  block lum   the mean over BxB blocks of |a - b| / b, a and b the blocks' mean luminances
              (Rec. 709 weights), and the mean signed (a - b) / b
  block rgb   the same per channel, averaged over the three channels
  pixel lum   the same per pixel
--mask leaves out every block holding a pixel that is not black in the mask (for instance
zonetrace's --level 0 image: the pixels that see a light directly); the means per channel keep
every pixel.  --rect adds the block figures inside rectangles of pixels (x0 y0 x1 y1, top-left
origin, end exclusive), to find where two images part.  --map writes the blocks' signed
luminance difference as a PPM (red: TEST brighter, green: darker, full at +-5%; masked blocks
blue).

mean writes the pixel-wise mean of the images (e.g. two seeds of one reference).

PFM rows are read bottom first and reported top first (row 0 at the top, as zonetrace's pixels).
"""
import array
import sys

LUM = (0.2126, 0.7152, 0.0722)


def read_pfm(path):
    with open(path, "rb") as f:
        magic = f.readline().strip()
        dims = f.readline().split()
        scale = float(f.readline().strip())
        if magic != b"PF" or len(dims) != 2:
            sys.exit("%s: not an RGB PFM file (one header field per line)" % path)
        w, h = int(dims[0]), int(dims[1])
        data = array.array("f")
        raw = f.read(w * h * 12)
        if len(raw) != w * h * 12:
            sys.exit("%s: truncated" % path)
        data.frombytes(raw)
    if (scale < 0) != (sys.byteorder == "little"):
        data.byteswap()
    # Top row first.
    rows = [data[(h - 1 - y) * w * 3:(h - y) * w * 3] for y in range(h)]
    return w, h, array.array("f", [v for r in rows for v in r])


def write_pfm(path, w, h, px):
    out = array.array("f")
    for y in range(h - 1, -1, -1):
        out.extend(px[y * w * 3:(y + 1) * w * 3])
    if sys.byteorder != "little":
        out.byteswap()
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(out.tobytes())


def block_means(w, h, px, b):
    """Per block: mean R, G, B, luminance; blocks in rows from the top."""
    bw, bh = w // b, h // b
    out = []
    for by in range(bh):
        for bx in range(bw):
            s = [0.0, 0.0, 0.0]
            for y in range(by * b, by * b + b):
                i = (y * w + bx * b) * 3
                for x in range(b):
                    s[0] += px[i]
                    s[1] += px[i + 1]
                    s[2] += px[i + 2]
                    i += 3
            n = b * b
            r, g, bl = s[0] / n, s[1] / n, s[2] / n
            out.append((r, g, bl, LUM[0] * r + LUM[1] * g + LUM[2] * bl))
    return bw, bh, out


def stats(pairs):
    """Mean |a-b|/b and mean (a-b)/b over pairs with b > 0; and how many were skipped."""
    sa = ss = 0.0
    n = skipped = 0
    for a, b in pairs:
        if b > 0:
            d = (a - b) / b
            sa += abs(d)
            ss += d
            n += 1
        else:
            skipped += 1
    return (sa / n if n else float("nan"), ss / n if n else float("nan"), n, skipped)


def diff(argv):
    import argparse
    ap = argparse.ArgumentParser(prog="cycles_compare.py diff")
    ap.add_argument("test")
    ap.add_argument("ref")
    ap.add_argument("--block", type=int, default=4)
    ap.add_argument("--mask")
    ap.add_argument("--map")
    ap.add_argument("--worst", type=int, default=0)
    ap.add_argument("--rect", type=int, nargs=4, action="append", default=[])
    a = ap.parse_args(argv)
    w, h, t = read_pfm(a.test)
    w2, h2, r = read_pfm(a.ref)
    if (w, h) != (w2, h2):
        sys.exit("the images differ in size: %dx%d and %dx%d" % (w, h, w2, h2))
    b = a.block
    n = w * h
    print("%s against %s, %dx%d" % (a.test, a.ref, w, h))
    for c, name in enumerate("RGB"):
        mt = sum(t[c::3]) / n
        mr = sum(r[c::3]) / n
        print("  mean %s   %10.5f %10.5f   %+.3f%%" % (name, mt, mr, 100 * (mt - mr) / mr))
    lt = sum(LUM[c] * sum(t[c::3]) for c in range(3)) / n
    lr = sum(LUM[c] * sum(r[c::3]) for c in range(3)) / n
    print("  mean lum %10.5f %10.5f   %+.3f%%" % (lt, lr, 100 * (lt - lr) / lr))
    bw, bh, bt = block_means(w, h, t, b)
    _, _, br = block_means(w, h, r, b)
    keep = [True] * (bw * bh)
    if a.mask:
        wm, hm, m = read_pfm(a.mask)
        if (wm, hm) != (w, h):
            sys.exit("the mask differs in size")
        for y in range(bh * b):
            for x in range(bw * b):
                i = (y * w + x) * 3
                if m[i] != 0 or m[i + 1] != 0 or m[i + 2] != 0:
                    keep[(y // b) * bw + x // b] = False
    kept = [k for k in range(bw * bh) if keep[k]]

    def report(label, ids):
        lum = stats((bt[k][3], br[k][3]) for k in ids)
        rgb = [stats((bt[k][c], br[k][c]) for k in ids) for c in range(3)]
        print("  %-26s %5d blocks: lum |d| %.3f%% (signed %+.3f%%), rgb |d| %.3f%% "
              "(R %.3f G %.3f B %.3f)"
              % (label, lum[2], 100 * lum[0], 100 * lum[1],
                 100 * sum(x[0] for x in rgb) / 3, 100 * rgb[0][0], 100 * rgb[1][0],
                 100 * rgb[2][0]))
        if lum[3]:
            print("    (%d blocks black in REF left out)" % lum[3])

    print("  %dx%d blocks: %d of %d kept%s" % (b, b, len(kept), bw * bh,
                                               " (mask %s)" % a.mask if a.mask else ""))
    report("all kept blocks", kept)
    for x0, y0, x1, y1 in a.rect:
        ids = [k for k in kept if x0 <= (k % bw) * b and (k % bw) * b + b <= x1 and
               y0 <= (k // bw) * b and (k // bw) * b + b <= y1]
        report("rect %d %d %d %d" % (x0, y0, x1, y1), ids)
    # Per pixel, in the kept blocks.
    pairs = []
    for y in range(bh * b):
        for x in range(bw * b):
            if keep[(y // b) * bw + x // b]:
                i = (y * w + x) * 3
                pairs.append((LUM[0] * t[i] + LUM[1] * t[i + 1] + LUM[2] * t[i + 2],
                              LUM[0] * r[i] + LUM[1] * r[i + 1] + LUM[2] * r[i + 2]))
    p = stats(pairs)
    print("  per pixel (kept blocks) %7d pixels: lum |d| %.3f%% (signed %+.3f%%)"
          % (p[2], 100 * p[0], 100 * p[1]))
    if a.worst:
        worst = sorted(kept, key=lambda k: -abs(bt[k][3] - br[k][3]) / max(br[k][3], 1e-30))
        for k in worst[:a.worst]:
            print("    block at x %4d y %4d: %10.4f against %10.4f (%+.2f%%)"
                  % ((k % bw) * b, (k // bw) * b, bt[k][3], br[k][3],
                     100 * (bt[k][3] - br[k][3]) / max(br[k][3], 1e-30)))
    if a.map:
        with open(a.map, "wb") as f:
            f.write(b"P6\n%d %d\n255\n" % (bw, bh))
            px = bytearray()
            for k in range(bw * bh):
                if not keep[k]:
                    px += bytes((0, 0, 255))
                    continue
                d = (bt[k][3] - br[k][3]) / br[k][3] if br[k][3] > 0 else 0.0
                v = int(max(0.0, min(1.0, abs(d) / 0.05)) * 255)
                px += bytes((v, 0, 0) if d > 0 else (0, v, 0))
            f.write(px)


def mean(argv):
    if len(argv) < 2:
        sys.exit("usage: cycles_compare.py mean OUT.pfm A.pfm [B.pfm ...]")
    images = [read_pfm(p) for p in argv[1:]]
    w, h = images[0][0], images[0][1]
    if any((x[0], x[1]) != (w, h) for x in images):
        sys.exit("the images differ in size")
    k = len(images)
    out = array.array("f", [0.0]) * (w * h * 3)
    for _, _, px in images:
        for i in range(w * h * 3):
            out[i] += px[i]
    for i in range(w * h * 3):
        out[i] /= k
    write_pfm(argv[0], w, h, out)


if __name__ == "__main__":
    if len(sys.argv) < 2 or sys.argv[1] not in ("diff", "mean"):
        sys.exit(__doc__)
    (diff if sys.argv[1] == "diff" else mean)(sys.argv[2:])
