# σ by region: where the light change moved the reference, does the blend move towards High-LR?
# For each run of a light-rotation experiment (nirc/scripts/paper_experiment.sh's RUNS_DIR/SCENE-seedN),
# pixels are split by how much the path-traced reference changed between frame BEFORE and frame
# AFTER (relative luminance change |La - Lb| / (La + Lb) of 9x9 box means, over the first run's
# references: they differ between seeds only by noise): "changed" (the share Q that changed most),
# "unchanged" (the share Q that changed least). Prints the blend's
# mean σ (frames/nirc_blend_1spp/preference/NNNN.png: green = σ, black = no query) in each class,
# before (frames BEFORE-9..BEFORE) and after (AFTER..AFTER+9), mean ± 95% interval over seeds.
# Pure Python (PNG via zlib; EXR: scanlines or single-level tiles, NONE/RLE/ZIP, float or half).
# Usage: python3 nirc/scripts/sigma_regions.py RUNS_DIR SCENE [BEFORE AFTER [Q]]   (19 30 0.2)
import glob, math, os, struct, sys, zlib

T975 = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306, 9: 2.262}


def read_png(path):
    """8-bit RGB/RGBA PNG -> (w, h, rows of channel tuples)."""
    d = open(path, 'rb').read()
    assert d[:8] == b'\x89PNG\r\n\x1a\n', path
    pos, idat, w = 8, b'', None
    while pos < len(d):
        n, kind = struct.unpack('>I4s', d[pos:pos + 8])
        body = d[pos + 8:pos + 8 + n]
        if kind == b'IHDR':
            w, h, depth, ctype = struct.unpack('>IIBB', body[:10])
            assert depth == 8 and ctype in (2, 6), f'{path}: only 8-bit RGB(A)'
            ch = 3 if ctype == 2 else 4
        elif kind == b'IDAT':
            idat += body
        pos += 12 + n
    raw, stride, prev, rows = zlib.decompress(idat), w * ch, bytearray(w * ch), []
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - ch] if i >= ch else 0
            b, c = prev[i], prev[i - ch] if i >= ch else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(line[x * ch:(x + 1) * ch]) for x in range(w)])
        prev = line
    return w, h, rows


def read_exr_luminance(path):
    """Scanline EXR (R, G, B float or half; NONE, RLE or ZIPS/ZIP) -> (w, h, luminance list)."""
    d = open(path, 'rb').read()
    pos, attrs = 8, {}
    while d[pos] != 0:
        name_end = d.index(b'\0', pos); name = d[pos:name_end].decode()
        type_end = d.index(b'\0', name_end + 1)
        size = struct.unpack('<i', d[type_end + 1:type_end + 5])[0]
        attrs[name] = d[type_end + 5:type_end + 5 + size]
        pos = type_end + 5 + size
    pos += 1
    chans, p, cl = [], 0, attrs['channels']
    while cl[p] != 0:
        e = cl.index(b'\0', p); pt = struct.unpack('<i', cl[e + 1:e + 5])[0]
        chans.append((cl[p:e].decode(), 4 if pt == 2 else 2)); p = e + 17
    x0, y0, x1, y1 = struct.unpack('<iiii', attrs['dataWindow'])
    w, h, comp = x1 - x0 + 1, y1 - y0 + 1, attrs['compression'][0]
    assert comp in (0, 1, 2, 3), f'{path}: compression {comp} (NONE, RLE, ZIPS or ZIP only)'
    if 'tiles' in attrs:  # single-level tiles (the exr crate writes these)
        tw, th = struct.unpack('<II', attrs['tiles'][:8])
        nx, ny = (w + tw - 1) // tw, (h + th - 1) // th
        nblocks = nx * ny
    else:
        tw, th = w, {0: 1, 1: 1, 2: 1, 3: 16}[comp]
        nblocks = (h + th - 1) // th
    offsets = struct.unpack(f'<{nblocks}Q', d[pos:pos + 8 * nblocks])
    lum = [0.0] * (w * h)
    for off in offsets:
        if 'tiles' in attrs:
            tx, ty, _, _, size = struct.unpack('<iiiii', d[off:off + 20]); data = d[off + 20:off + 20 + size]
            bx, by = tx * tw, ty * th
        else:
            y, size = struct.unpack('<ii', d[off:off + 8]); data = d[off + 8:off + 8 + size]
            bx, by = 0, y - y0
        bw, bh = min(tw, w - bx), min(th, h - by)
        expect = bh * bw * sum(s for _, s in chans)
        if comp != 0 and size < expect:
            if comp == 1:
                out, i = bytearray(), 0
                while i < len(data):
                    c = struct.unpack('b', data[i:i + 1])[0]
                    if c < 0: out += data[i + 1:i + 1 - c]; i += 1 - c
                    else: out += data[i + 1:i + 2] * (c + 1); i += 2
            else:
                out = bytearray(zlib.decompress(data))
            for i in range(1, len(out)):
                out[i] = (out[i - 1] + out[i] - 128) & 255
            half = (len(out) + 1) // 2
            data = bytearray(len(out)); data[0::2] = out[:half]; data[1::2] = out[half:]
        data, q = bytes(data), 0
        for line in range(bh):
            vals = {}
            for name, s in chans:
                fmt = f'<{bw}f' if s == 4 else f'<{bw}e'
                vals[name] = struct.unpack(fmt, data[q:q + bw * s]); q += bw * s
            row = (by + line) * w + bx
            for x in range(bw):
                lum[row + x] = 0.2126 * vals['R'][x] + 0.7152 * vals['G'][x] + 0.0722 * vals['B'][x]
    return w, h, lum


def srgb_to_linear(v):
    # write_png_linear stores σ sRGB-encoded.
    return v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4


def box_blur(img, w, h, r):
    out = [0.0] * (w * h)
    for y in range(h):
        for x in range(w):
            s, n = 0.0, 0
            for yy in range(max(0, y - r), min(h, y + r + 1)):
                row = yy * w
                for xx in range(max(0, x - r), min(w, x + r + 1)):
                    s += img[row + xx]; n += 1
            out[y * w + x] = s / n
    return out


def mean_ci(v):
    m = sum(v) / len(v)
    if len(v) < 2: return m, float('nan')
    s = math.sqrt(sum((x - m) ** 2 for x in v) / (len(v) - 1))
    return m, T975.get(len(v) - 1, 1.96) * s / math.sqrt(len(v))


def main():
    runs, scene = sys.argv[1], sys.argv[2]
    before, after = (int(a) for a in sys.argv[3:5]) if len(sys.argv) > 4 else (19, 30)
    q = float(sys.argv[5]) if len(sys.argv) > 5 else 0.2
    seeds = sorted(d for d in glob.glob(os.path.join(runs, f'{scene}-seed*')) if os.path.isdir(d))
    assert seeds, f'no {scene}-seed* runs under {runs}'
    w, h, lb = read_exr_luminance(os.path.join(seeds[0], 'reference', f'{before:04}.exr'))
    _, _, la = read_exr_luminance(os.path.join(seeds[0], 'reference', f'{after:04}.exr'))
    # A 128-spp reference is noisy pixel by pixel: compare 9x9 box means (the change of interest
    # is a region's lighting, and the reliability grid's cells span several pixels too).
    lb, la = box_blur(lb, w, h, 4), box_blur(la, w, h, 4)
    change = [abs(a - b) / (a + b) if a + b > 1e-6 else 0.0 for a, b in zip(la, lb)]
    # Classes by quantile, so that every scene has both: the share q of pixels whose lighting
    # changed most, and the share q that changed least.
    ranked = sorted(change)
    lo, hi = ranked[int(q * (len(ranked) - 1))], ranked[int((1 - q) * (len(ranked) - 1))]
    cls = ['changed' if c >= hi else 'unchanged' if c <= lo else None for c in change]
    mean_change = {k: sum(c for c, k2 in zip(change, cls) if k2 == k) / max(1, cls.count(k)) for k in ('changed', 'unchanged')}
    res = {}
    for run in seeds:
        for window, frames in (('before', range(before - 9, before + 1)), ('after', range(after, after + 10))):
            acc = {'changed': [0.0, 0], 'unchanged': [0.0, 0]}
            for f in frames:
                path = os.path.join(run, 'frames', 'nirc_blend_1spp', 'preference', f'{f:04}.png')
                if not os.path.exists(path): continue
                pw, ph, rows = read_png(path)
                assert (pw, ph) == (w, h), path
                for y in range(h):
                    for x in range(w):
                        k, px = cls[y * w + x], rows[y][x]
                        if k and (px[0] or px[1]):
                            acc[k][0] += srgb_to_linear(px[1] / 255.0); acc[k][1] += 1
            for k, (s, n) in acc.items():
                if n: res.setdefault((window, k), []).append(s / n)
    print(f'### {scene}: the blend\'s mean σ by how much the reference changed (frames {before} → {after})\n')
    print(f'Pixels: the {100 * q:.0f}% whose reference changed most (relative luminance change of 9x9 means ≥ {hi:.3f}, mean {mean_change["changed"]:.3f}) '
          f'and the {100 * q:.0f}% that changed least (≤ {lo:.3f}, mean {mean_change["unchanged"]:.3f}); {len(seeds)} seeds.\n')
    print('| window | σ, changed | σ, unchanged |\n|---|---:|---:|')
    for window in ('before', 'after'):
        cells = []
        for k in ('changed', 'unchanged'):
            v = res.get((window, k), [])
            cells.append('n/a' if not v else '%.3f ± %.3f' % mean_ci(v))
        print(f'| {window} | {cells[0]} | {cells[1]} |')


if __name__ == '__main__':
    main()
