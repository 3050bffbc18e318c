#!/usr/bin/env python3
"""smallpt's pixel filter applied to an image rendered at 4 times the size.

smallpt splits each pixel into 2 x 2 subpixels and offsets each sample from
its subpixel's centre by a tent-distributed dx, dy in [-1, 1] subpixels, so
a subpixel sees a tent of half-width half a pixel centred on it, and the
pixel the mean of its four subpixels' tents: separable, along each axis
f(u) = (t(u - 1/4) + t(u - 3/4)) / 2, u in pixels from the pixel's edge,
t(s) = 4 (1/2 - |s|) on |s| < 1/2.  Over an image 4 times finer (quarter-
pixel cells j = -1 .. 4, j covering [j/4, (j+1)/4]) its integrals are
1/16, 3/16, 1/4, 1/4, 3/16, 1/16: the weights used here on each axis.

  smallpt_filter.py scene SCENE.json OUT.json W H
      writes SCENE with its screen grown by a quarter of a W x H pixel on
      each side; render OUT.json at (4W + 2) x (4H + 2), a margin of one
      fine pixel around the 4W x 4H image the filter reaches into
  smallpt_filter.py filter FINE.pfm OUT.pfm
      filters a (4W + 2) x (4H + 2) PFM down to W x H
  smallpt_filter.py box FINE.pfm OUT.pfm
      the same image with a box filter over each pixel instead: the mean
      of its 4 x 4 fine pixels (the margin left out)

Pure Python (no numpy), so that any python3 runs it.
"""
import array
import json
import sys

WEIGHTS = (1 / 16, 3 / 16, 1 / 4, 1 / 4, 3 / 16, 1 / 16)


def grow_screen(src, dst, w, h):
    scene = json.load(open(src))
    tl, tr, bl, br = [list(map(float, p)) for p in scene["camera"]["screen"]]
    fw, fh = 4 * w, 4 * h
    u = [(b - a) / fw for a, b in zip(tl, tr)]  # one fine pixel rightwards
    v = [(b - a) / fh for a, b in zip(tl, bl)]  # one fine pixel downwards
    def at(p, su, sv):
        return [p[k] + su * u[k] + sv * v[k] for k in range(3)]
    scene["camera"]["screen"] = [at(tl, -1, -1), at(tr, 1, -1),
                                 at(bl, -1, 1), at(br, 1, 1)]
    scene["camera"]["gridresolution"] = [fw + 2, fh + 2]
    json.dump(scene, open(dst, "w"), indent=1)


def read_pfm(path):
    with open(path, "rb") as f:
        words = []
        while len(words) < 4:
            words += f.readline().split()
        if words[0] != b"PF":
            sys.exit("smallpt_filter: %s is not an RGB PFM" % path)
        w, h, scale = int(words[1]), int(words[2]), float(words[3])
        data = array.array("f")
        data.frombytes(f.read(w * h * 12))
    if (scale < 0) != (sys.byteorder == "little"):
        data.byteswap()
    return w, h, data


def write_pfm(path, w, h, data):
    if sys.byteorder != "little":
        data = array.array("f", data)
        data.byteswap()
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(data.tobytes())


def fine_size(src):
    fw, fh, fine = read_pfm(src)
    if (fw - 2) % 4 or (fh - 2) % 4 or fw < 6 or fh < 6:
        sys.exit("smallpt_filter: %s is %d x %d, not (4W + 2) x (4H + 2)"
                 % (src, fw, fh))
    return fw, fh, fine, (fw - 2) // 4, (fh - 2) // 4


def box_image(src, dst):
    fw, fh, fine, w, h = fine_size(src)
    result = array.array("f")
    for y in range(h):
        r = [fine[3 * fw * (4 * y + 1 + k):3 * fw * (4 * y + 2 + k)] for k in range(4)]
        col = [a + b + c + d for a, b, c, d in zip(*r)]  # 4 fine rows summed
        for x in range(w):
            for ch in range(3):
                i = 3 * (4 * x + 1) + ch
                result.append((col[i] + col[i + 3] + col[i + 6] + col[i + 9]) / 16)
    write_pfm(dst, w, h, result)


def filter_image(src, dst):
    fw, fh, fine, w, h = fine_size(src)
    w0, w1, w2, w3, w4, w5 = WEIGHTS
    # Along each row: out[x] = sum_k WEIGHTS[k] * row[4x + k], per channel.
    rows = []
    for y in range(fh):
        row = fine[3 * fw * y:3 * fw * (y + 1)]
        out = [0.0] * (3 * w)
        for ch in range(3):
            c = row[ch::3]
            out[ch::3] = [w0 * c[i] + w1 * c[i + 1] + w2 * c[i + 2]
                          + w3 * c[i + 3] + w4 * c[i + 4] + w5 * c[i + 5]
                          for i in range(0, 4 * w, 4)]
        rows.append(out)
    # Down the columns, the same (the weights are symmetric, so the PFM's
    # bottom-up row order does not matter).
    result = array.array("f")
    for y in range(h):
        r = rows[4 * y:4 * y + 6]
        result.extend([w0 * a + w1 * b + w2 * c + w3 * d + w4 * e + w5 * g
                       for a, b, c, d, e, g in zip(*r)])
    write_pfm(dst, w, h, result)


def main(argv):
    if len(argv) == 6 and argv[1] == "scene":
        grow_screen(argv[2], argv[3], int(argv[4]), int(argv[5]))
    elif len(argv) == 4 and argv[1] == "filter":
        filter_image(argv[2], argv[3])
    elif len(argv) == 4 and argv[1] == "box":
        box_image(argv[2], argv[3])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv)
