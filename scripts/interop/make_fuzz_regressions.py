#!/usr/bin/env python3
"""Writes the regression inputs of the outside mutation pass's cases into fuzz/regressions/:
each is replayed by tests/fuzz/test_fuzz_corpus.cpp and must end in one sadsplat::Error (or a
documented correct read), quickly. Run from the repository root: python3 scripts/interop/make_fuzz_regressions.py"""
import gzip
import os
import struct
import zipfile
import io

root = os.path.join(os.path.dirname(__file__), '..', '..', 'fuzz', 'regressions')
REQUIRED = ['x', 'y', 'z', 'f_dc_0', 'f_dc_1', 'f_dc_2', 'opacity', 'scale_0', 'scale_1',
            'scale_2', 'rot_0', 'rot_1', 'rot_2', 'rot_3']


def write(kind, name, data):
    os.makedirs(os.path.join(root, kind), exist_ok=True)
    with open(os.path.join(root, kind, name), 'wb') as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def ascii_ply(values, extra=''):
    head = 'ply\nformat ascii 1.0\nelement vertex 1\n'
    head += ''.join('property float %s\n' % n for n in REQUIRED)
    return head + extra + 'end_header\n' + values + '\n'


def zip_entry(z, name, text):
    info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))  # deterministic bytes
    info.compress_type = z.compression
    z.writestr(info, text)


def legacy_spz(count, payload, version=3, degree=3):
    return gzip.compress(struct.pack('<IIIBBBB', 0x5053474e, version, count, degree, 12, 0, 0)
                         + payload, 9, mtime=0)  # deterministic bytes


# SPZ: a small gzip whose header claims 40 Gaussians and inflates to 16 MB (a bomb); version 1;
# a version-4 header claiming 2^27 Gaussians in 64 bytes; a version-4 table past the end.
write('splat_formats', 'gzip_bomb.spz', legacy_spz(40, bytes(16 << 20)))
write('splat_formats', 'version1.spz', legacy_spz(40, bytes(40 * 20), version=1))
write('splat_formats', 'bad_degree.spz', legacy_spz(40, bytes(4096), degree=9))
v4 = struct.pack('<IIIBBBBI', 0x5053474e, 4, 1 << 27, 0, 12, 0, 5, 32) + bytes(12)
write('splat_formats', 'v4_huge_count.spz', v4 + bytes(32))
v4 = struct.pack('<IIIBBBBI', 0x5053474e, 4, 2, 0, 12, 0, 5, 32) + bytes(12)
write('splat_formats', 'v4_toc_past_end.spz', v4 + struct.pack('<QQ', 1 << 40, 18))
write('splat_formats', 'empty.splat', b'')
# SOG: a ZIP without meta.json; one whose meta.json is version 1; one with absurd image sizes.
buf = io.BytesIO()
with zipfile.ZipFile(buf, 'w') as z:
    zip_entry(z, 'other.txt', 'x')
write('splat_formats', 'sog_no_meta.sog', buf.getvalue())
buf = io.BytesIO()
with zipfile.ZipFile(buf, 'w') as z:
    zip_entry(z, 'meta.json', '{"means": {"shape": [1, 3]}}')
write('splat_formats', 'sog_version1.sog', buf.getvalue())
buf = io.BytesIO()
with zipfile.ZipFile(buf, 'w', zipfile.ZIP_DEFLATED) as z:
    zip_entry(z, 'meta.json', '{"version": 2, "count": 1e30}')
write('splat_formats', 'sog_huge_count.sog', buf.getvalue())

# 3DGS PLY: values beyond float range or plausibility, an infinite opacity (clamped, a correct
# read), and 10^9 trailing camera records with no bytes behind them.
write('gaussian_ply', 'ascii_1e39.ply', ascii_ply('1e39 0 0 0 0 0 0 0 0 0 1 0 0 0'))
write('gaussian_ply', 'absurd_x.ply', ascii_ply('-3.4e38 0 0 0 0 0 0 0 0 0 1 0 0 0'))
write('gaussian_ply', 'absurd_log_scale.ply', ascii_ply('0 0 0 0 0 0 0 1e30 0 0 1 0 0 0'))
write('gaussian_ply', 'inf_opacity.ply', ascii_ply('0 0 0 0 0 0 inf 0 0 0 1 0 0 0'))
write('gaussian_ply', 'trailing_cameras.ply',
      ascii_ply('0 0 0 0 0 0 0 0 0 0 1 0 0 0', 'element camera 1000000000\nproperty float fx\n'))
head = 'ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty double x\n'
head += ''.join('property float %s\n' % n for n in REQUIRED[1:]) + 'end_header\n'
write('gaussian_ply', 'double_1e300.ply', head.encode() + struct.pack('<d', 1e300) + bytes(52))
# A compressed PLY whose chunk count does not match its vertices.
head = ('ply\nformat binary_little_endian 1.0\nelement chunk 5\n' +
        ''.join('property float %s\n' % n for n in
                ['min_x', 'min_y', 'min_z', 'max_x', 'max_y', 'max_z', 'min_scale_x',
                 'min_scale_y', 'min_scale_z', 'max_scale_x', 'max_scale_y', 'max_scale_z']) +
        'element vertex 1\n' +
        ''.join('property uint %s\n' % n for n in
                ['packed_position', 'packed_rotation', 'packed_scale', 'packed_color']) +
        'end_header\n')
write('gaussian_ply', 'compressed_chunk_count.ply', head.encode() + bytes(5 * 48 + 16))

# PCD: an 8-byte float beyond float range.
write('pcd', 'double_1e300.pcd',
      'FIELDS x y z rgb label\nSIZE 8 4 4 4 4\nTYPE F F F F U\nCOUNT 1 1 1 1 1\nWIDTH 1\n'
      'HEIGHT 1\nPOINTS 1\nDATA ascii\n1e300 0 0 0 1\n')
