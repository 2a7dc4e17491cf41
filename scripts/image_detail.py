#!/usr/bin/env python3
"""How much fine detail a picture holds: the share of its spectral energy in the upper half of
its wavenumbers.

The luminance of the PNG (mean removed, Hann window against the edges' jump) is transformed with a
2D FFT; the share is the power at radial wavenumbers above half the Nyquist frequency over the
power at all nonzero wavenumbers. A smooth smear scores near 0; wisps and curls raise it.

    scripts/image_detail.py [--crop X0 Y0 X1 Y1] PICTURE.png [MORE.png ...]

--crop measures the pixels X0 <= x < X1, Y0 <= y < Y1 only (y from the top), e.g. the part of the
picture above an obstacle whose sharp edges would count as detail. Prints one line per picture:
the share and the file. Standard library only (zlib for the PNG,
a radix-2 FFT), a few seconds for a 640 x 480 picture.
"""
import cmath
import math
import struct
import sys
import zlib


def read_png_luminance(path):
    """Rows of luminance in [0, 1] of an 8-bit, non-interlaced grey, RGB or RGBA PNG."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG file")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(colour)
    if depth != 8 or channels is None or interlace != 0:
        sys.exit(f"{path}: only 8-bit non-interlaced grey/RGB/RGBA PNGs are supported")
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        kind, line = raw[start], bytearray(raw[start + 1:start + 1 + stride])
        for i in range(stride):
            left = line[i - channels] if i >= channels else 0
            up = previous[i]
            upper_left = previous[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + left) & 255
            elif kind == 2:
                line[i] = (line[i] + up) & 255
            elif kind == 3:
                line[i] = (line[i] + ((left + up) >> 1)) & 255
            elif kind == 4:
                p = left + up - upper_left
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - upper_left)
                predictor = left if pa <= pb and pa <= pc else (up if pb <= pc else upper_left)
                line[i] = (line[i] + predictor) & 255
        previous = line
        if channels >= 3:
            rows.append([(0.2126 * line[x * channels] + 0.7152 * line[x * channels + 1] +
                          0.0722 * line[x * channels + 2]) / 255.0 for x in range(width)])
        else:
            rows.append([line[x * channels] / 255.0 for x in range(width)])
    return rows


def fft(values):
    """In-place iterative radix-2 FFT of a list of complex numbers (length a power of two)."""
    n = len(values)
    j = 0
    for i in range(1, n):
        bit = n >> 1
        while j & bit:
            j ^= bit
            bit >>= 1
        j |= bit
        if i < j:
            values[i], values[j] = values[j], values[i]
    size = 2
    while size <= n:
        step = cmath.exp(-2j * math.pi / size)
        for start in range(0, n, size):
            w = 1.0
            for k in range(size // 2):
                a, b = values[start + k], values[start + k + size // 2] * w
                values[start + k], values[start + k + size // 2] = a + b, a - b
                w *= step
        size *= 2
    return values


def upper_half_share(rows):
    height, width = len(rows), len(rows[0])
    mean = sum(map(sum, rows)) / (width * height)
    ny, nx = 1 << (height - 1).bit_length(), 1 << (width - 1).bit_length()
    hann_x = [0.5 - 0.5 * math.cos(2 * math.pi * (x + 0.5) / width) for x in range(width)]
    hann_y = [0.5 - 0.5 * math.cos(2 * math.pi * (y + 0.5) / height) for y in range(height)]
    spectrum = []
    for y in range(ny):
        line = [0j] * nx
        if y < height:
            for x in range(width):
                line[x] = complex((rows[y][x] - mean) * hann_x[x] * hann_y[y])
        spectrum.append(fft(line))
    upper = total = 0.0
    for kx in range(nx):
        column = fft([spectrum[y][kx] for y in range(ny)])
        fx = min(kx, nx - kx) / nx
        for ky in range(ny):
            fy = min(ky, ny - ky) / ny
            if kx == 0 and ky == 0:
                continue
            power = abs(column[ky]) ** 2
            total += power
            if math.hypot(fx, fy) > 0.25:  # half of the Nyquist frequency 0.5
                upper += power
    return upper / total if total > 0 else 0.0


def main():
    args = sys.argv[1:]
    crop = None
    if args[:1] == ["--crop"]:
        if len(args) < 6:
            sys.exit("--crop needs X0 Y0 X1 Y1")
        crop = [int(v) for v in args[1:5]]
        args = args[5:]
    if not args:
        sys.exit(__doc__)
    for path in args:
        rows = read_png_luminance(path)
        if crop:
            x0, y0, x1, y1 = crop
            rows = [row[x0:x1] for row in rows[y0:y1]]
            if not rows or not rows[0]:
                sys.exit(f"{path}: the crop {crop} leaves no pixels")
        print(f"{upper_half_share(rows):.3e}  {path}")


if __name__ == "__main__":
    main()
