"""Hand-made bad inputs for sadsplat's readers: the regression inputs of fuzz/regressions/ and the
seeds the mutation pass (mutation_pass.py) starts from. Standard library only.

    python3 scripts/reliability/inputs.py regressions fuzz/regressions   # (re)write the regressions
    python3 scripts/reliability/inputs.py seeds fuzz/corpus               # good inputs, new targets
"""
import json
import math
import os
import struct
import sys
import zlib

# ---------------------------------------------------------------------------------------------
# Writers of valid files, so that each bad input differs from a good one in one field.


def png(width, height, colour_type=0, pixels=None, bit_depth=8):
    """A PNG of width x height; `pixels` the filtered scanlines (None: a cut-off IDAT)."""
    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))
    ihdr = struct.pack(">IIBBBBB", width, height, bit_depth, colour_type, 0, 0, 0)
    body = chunk(b"IHDR", ihdr)
    body += chunk(b"IDAT", zlib.compress(pixels if pixels is not None else b"\0" * 64))
    body += chunk(b"IEND", b"")
    return b"\x89PNG\r\n\x1a\n" + body


def jpeg_claiming(width, height, total=676):
    """A baseline JPEG header whose frame claims width x height, padded to `total` bytes."""
    soi = b"\xff\xd8"
    app0 = b"\xff\xe0" + struct.pack(">H", 16) + b"JFIF\0\x01\x01\0\0\x01\0\x01\0\0"
    dqt = b"\xff\xdb" + struct.pack(">H", 67) + b"\0" + bytes([1] * 64)
    sof = b"\xff\xc0" + struct.pack(">HBHHB", 11, 8, height, width, 1) + b"\x01\x11\x00"
    dht = (b"\xff\xc4" + struct.pack(">H", 31) + b"\x00" + bytes([0, 1, 5, 1, 1, 1, 1, 1, 1, 0, 0,
           0, 0, 0, 0, 0]) + bytes(range(12)))
    sos = b"\xff\xda" + struct.pack(">HB", 8, 1) + b"\x01\x00\x00\x3f\x00"
    head = soi + app0 + dqt + sof + dht + sos
    return head + b"\0" * max(0, total - len(head) - 2) + b"\xff\xd9"


def las(points, scale=(0.001,) * 3, offset=(0.0,) * 3, bounds=None, wkt=b"", classes=None):
    """A LAS 1.4 point format 7 file of (x, y, z) points; `bounds` overrides the header's
    (min x, max x, ...) as (minx, maxx, miny, maxy, minz, maxz)."""
    n = len(points)
    vlr = b""
    if wkt:
        vlr = (struct.pack("<H", 0) + b"LASF_Projection".ljust(16, b"\0") + struct.pack("<HH", 2112,
               len(wkt)) + b"WKT".ljust(32, b"\0") + wkt)
    header_size = 375
    offset_to_data = header_size + len(vlr)
    h = bytearray(header_size)
    h[0:4] = b"LASF"
    struct.pack_into("<H", h, 6, 1 << 4 if wkt else 0)  # global encoding: WKT
    h[24], h[25] = 1, 4
    h[26:58] = b"sadsplat-test".ljust(32, b"\0")
    h[58:90] = b"sadsplat-test".ljust(32, b"\0")
    struct.pack_into("<HIIBHI", h, 94, header_size, offset_to_data, 1 if wkt else 0, 7, 36, 0)
    struct.pack_into("<3d", h, 131, *scale)
    struct.pack_into("<3d", h, 155, *offset)
    if bounds is None:
        lo = [min(p[k] for p in points) if points else 0 for k in range(3)]
        hi = [max(p[k] for p in points) if points else 0 for k in range(3)]
        bounds = (lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])
    minx, maxx, miny, maxy, minz, maxz = bounds
    struct.pack_into("<6d", h, 179, maxx, minx, maxy, miny, maxz, minz)
    struct.pack_into("<Q", h, 247, n)
    records = b""
    for i, p in enumerate(points):
        xi = [int(round((p[k] - offset[k]) / scale[k])) if scale[k] and math.isfinite(scale[k])
              else 0 for k in range(3)]
        cls = classes[i] if classes else 2
        records += struct.pack("<iiiHBBBBhH d HHH", *xi, 0, 0x11, 0, cls, 0, 0, 0, 0.0, 0, 0, 0)
    return bytes(h) + vlr + records


def las_patched(data, offset, fmt, *values):
    b = bytearray(data)
    struct.pack_into(fmt, b, offset, *values)
    return bytes(b)


# The fixture scene (data/tiny_scene): 8 views view_000.png .. view_007.png of 64x48, classes
# road, grass, building.
VIEWS = ["view_%03d.png" % i for i in range(8)]
W, H = 64, 48


def transforms(top_overrides=None, **frame_overrides):
    frames = []
    for i, name in enumerate(VIEWS):
        angle = 2 * math.pi * i / len(VIEWS)
        c, s = math.cos(angle), math.sin(angle)
        # Cameras on a circle of radius 6 at height 4, looking at the origin (OpenGL axes).
        centre = [6 * c, 6 * s, 4]
        f = [-x / math.sqrt(sum(y * y for y in centre)) for x in centre]
        right = [-f[1], f[0], 0]
        rn = math.sqrt(sum(x * x for x in right))
        right = [x / rn for x in right]
        up = [right[1] * f[2] - right[2] * f[1], right[2] * f[0] - right[0] * f[2],
              right[0] * f[1] - right[1] * f[0]]
        m = [[right[k], up[k], -f[k], centre[k]] for k in range(3)] + [[0, 0, 0, 1]]
        frames.append({"file_path": "images/" + name, "transform_matrix": m})
    top = {"fl_x": 52, "fl_y": 52, "cx": 32, "cy": 24, "w": W, "h": H, "frames": frames}
    for k, v in frame_overrides.items():
        frames[0][k] = v
    for k, v in (top_overrides or {}).items():
        if v is None:
            del top[k]
        else:
            top[k] = v
    return top


def labelme(shapes, image="view_000.png"):
    return {"version": "5.2.1", "shapes": shapes, "imagePath": image, "imageWidth": W,
            "imageHeight": H}


def coco(images=None, annotations=None, categories=None):
    return {
        "images": images if images is not None else [
            {"id": i + 1, "file_name": n, "width": W, "height": H} for i, n in enumerate(VIEWS[:2])],
        "annotations": annotations if annotations is not None else [
            {"id": 1, "image_id": 1, "category_id": 1,
             "segmentation": [[0, 0, 30, 0, 30, 20, 0, 20]]}],
        "categories": categories if categories is not None else [
            {"id": 1, "name": "road"}, {"id": 2, "name": "grass"}, {"id": 3, "name": "building"}],
    }


def georeference(**overrides):
    g = {"origin": {"latitude": 50.8, "longitude": -0.13, "altitude": 20.0}, "epsg_utm": 32630,
         "sfm_to_local": {"scale": 1.0, "rotation": [1, 0, 0, 0, 1, 0, 0, 0, 1],
                          "translation": [0, 0, 0]}}
    g.update(overrides)
    return g


def text(value):
    return json.dumps(value).encode()


# ---------------------------------------------------------------------------------------------
# The regression inputs: one per defect kind of the outside pass (and its examples), per target.
# Each line of expected.tsv: target/file, then "ok" (a correct read) or a piece of the one-line
# error that must come out.

def regressions():
    good_points = [(0.0, 0.0, 0.0), (1.0, 2.0, 3.0), (10.0, -5.0, 2.5)]
    r = {}
    # 1. valid JSON, not what the reader expects
    r["transforms_json/number_1e400.json"] = (
        text(transforms()).replace(b'"fl_x": 52', b'"fl_x": 1e400'), "within double's range")
    r["annotations/labelme_shape_type_number.json"] = (text(labelme([
        {"label": "road", "points": [[0, 0], [10, 0], [10, 10]], "shape_type": 7}])),
        "shape_type: expected a string")
    r["annotations/labelme_shape_type_null.json"] = (text(labelme([
        {"label": "road", "points": [[0, 0], [10, 0], [10, 10]], "shape_type": None}])), "ok")
    r["annotations/coco_category_without_id.json"] = (text(coco(categories=[{"name": "road"}])),
                                                      "categories[0].id: expected a value")
    r["annotations/coco_image_without_id.json"] = (text(coco(images=[
        {"file_name": "view_000.png", "width": W, "height": H}])), "images[0].id")
    r["annotations/coco_annotation_without_image_id.json"] = (text(coco(annotations=[
        {"id": 1, "category_id": 1, "segmentation": [[0, 0, 9, 0, 9, 9]]}])),
        "annotations[0].image_id")
    r["annotations/coco_annotation_without_category_id.json"] = (text(coco(annotations=[
        {"id": 1, "image_id": 1, "segmentation": [[0, 0, 9, 0, 9, 9]]}])),
        "annotations[0].category_id")
    r["annotations/coco_annotation_a_string.json"] = (text(coco(annotations=["road"])),
                                                      "annotations[0]: expected an object")
    r["annotations/coco_rle_without_size.json"] = (text(coco(annotations=[
        {"id": 1, "image_id": 1, "category_id": 1, "segmentation": {"counts": [3072]}}])),
        "segmentation.size")
    r["annotations/coco_rle_without_counts.json"] = (text(coco(annotations=[
        {"id": 1, "image_id": 1, "category_id": 1, "segmentation": {"size": [H, W]}}])),
        "segmentation.counts")
    # 3. images whose header claims too many pixels
    r["photo/png_60000x60000.png"] = (png(60000, 60000), "header size")
    r["photo/jpeg_30000x30000_676_bytes.png"] = (jpeg_claiming(30000, 30000), "header size")
    r["photo/jpeg_10000x10000_676_bytes.png"] = (jpeg_claiming(10000, 10000), "bytes can hold")
    r["photo/jpeg_60000x60000.png"] = (jpeg_claiming(60000, 60000), "header size")
    r["label_png/png_60000x60000.png"] = (png(60000, 60000), "header size")
    # 4. allocations sized by a header
    r["annotations/coco_rle_huge.json"] = (text(coco(
        images=[{"id": 1, "file_name": "view_000.png", "width": 750000, "height": 1000000}],
        annotations=[{"id": 1, "image_id": 1, "category_id": 1,
                      "segmentation": {"size": [1000000, 750000], "counts": [750000000000]}}])),
        "images[0] size: expected an image of at most 268435456 pixels")
    # 5. import must not write a cache its reader refuses
    r["transforms_json/fl_x_1e-300.json"] = (
        text(transforms(fl_x=1e-300, fl_y=1e-300)), "at least 0.001 px")
    r["transforms_json/camera_angle_y_0.json"] = (
        text(transforms({"fl_x": None, "fl_y": None, "camera_angle_x": 1.0, "camera_angle_y": 0})), "camera_angle_y")
    r["transforms_json/camera_angle_y_pi.json"] = (
        text(transforms({"fl_x": None, "fl_y": None, "camera_angle_x": 1.0,
                         "camera_angle_y": math.pi})), "camera_angle_y")
    r["transforms_json/w_1e300.json"] = (text(transforms(w=1e300)), "w / h")
    # 6. silent integer wraps
    r["annotations/labelme_rectangle_beyond_the_image.json"] = (text(labelme([
        {"label": "road", "points": [[-50000, -50000], [90000, 90000]],
         "shape_type": "rectangle"}])), "ok")
    r["annotations/labelme_vertices_1e308.json"] = (text(labelme([
        {"label": "road", "points": [[-1e308, 0], [1e308, 0], [0, 1e308]]}])),
        "expected a number in [")
    r["annotations/coco_rle_count_2_32.json"] = (text(coco(annotations=[
        {"id": 1, "image_id": 1, "category_id": 1,
         "segmentation": {"size": [H, W], "counts": [2 ** 32, W * H]}}])),
        "counts[0]: expected an integer in [0, 3072]")
    # 7. duplicate COCO image ids
    r["annotations/coco_duplicate_image_id.json"] = (text(coco(images=[
        {"id": 1, "file_name": "view_000.png", "width": W, "height": H},
        {"id": 1, "file_name": "view_001.png", "width": W, "height": H}])),
        "an id no other image has")
    # 8. LAS scale, offset and bounds
    good = las(good_points)
    r["las/good.las"] = (good, "ok")
    for name, value in [("0", 0.0), ("nan", float("nan")), ("inf", float("inf")),
                        ("1e308", 1e308)]:
        r["las/scale_%s.las" % name] = (las_patched(good, 131, "<d", value), "X scale factor")
    r["las/offset_nan.las"] = (las_patched(good, 163, "<d", float("nan")), "Y offset")
    r["las/offset_1e308.las"] = (las_patched(good, 171, "<d", 1e308), "Z offset")
    r["las/bounds_nan.las"] = (las_patched(good, 179, "<d", float("nan")), "min / max X")
    r["las/bounds_disagree.las"] = (las(good_points, bounds=(0, 1, 0, 1, 0, 1)),
                                    "bounds that hold the points")
    r["las/count_beyond_the_file.las"] = (las_patched(good, 247, "<Q", 10 ** 9),
                                          "number of point records")
    # 9. control bytes (a correct read; the unit test checks what info prints)
    r["las/wkt_with_escape.las"] = (las(good_points, wkt=b'PROJCS["\x1b[2J evil",UNIT["m",1]]'),
                                    "ok")
    # 10. georeference.json
    r["georeference/good.json"] = (text(georeference()), "ok")
    r["georeference/epsg_4326.json"] = (text(georeference(epsg_utm=4326)), "EPSG:32630")
    r["georeference/epsg_south.json"] = (text(georeference(epsg_utm=32730)), "EPSG:32630")
    r["georeference/altitude_1e308.json"] = (text(georeference(
        origin={"latitude": 50.8, "longitude": -0.13, "altitude": 1e308})), "origin.altitude")
    r["georeference/rotation_short.json"] = (text(georeference(sfm_to_local={
        "scale": 1, "rotation": [1, 0, 0], "translation": [0, 0, 0]})), "sfm_to_local.rotation")
    r["georeference/inliers_1e300.json"] = (text(georeference(inliers=1e300)), "inliers")
    r["georeference/number_1e400.json"] = (text(georeference()).replace(b"50.8", b"1e400"),
                                           "within double's range")
    # 14. grey + alpha label map: a correct read (grey = class id, transparent = ignore)
    rows = []
    for y in range(H):
        row = b"\0"
        for x in range(W):
            row += bytes([x * 3 // W, 255 if y < 40 else 0])
        rows.append(row)
    r["label_png/grey_alpha.png"] = (png(W, H, colour_type=4, pixels=b"".join(rows)), "ok")
    # 15. near the limit: a zip entry that claims to inflate 1000-fold
    return r


def write_regressions(root):
    expected = []
    for name, (data, outcome) in sorted(regressions().items()):
        path = os.path.join(root, name)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as f:
            f.write(data)
        expected.append("%s\t%s" % (name, outcome))
    with open(os.path.join(root, "expected.tsv"), "w") as f:
        f.write("# fuzz/regressions/<target>/<file> <TAB> \"ok\" (read correctly) or a piece of "
                "the one-line error it must give\n")
        f.write("# written by scripts/reliability/inputs.py regressions fuzz/regressions\n")
        f.write("\n".join(expected) + "\n")
    print("%d regression inputs in %s" % (len(expected), root))


def seeds():
    """One good input per reader that the hand-made inputs cover (the fuzzers' and the mutation
    pass's starting points)."""
    return {
        "las/good.las": las([(0.0, 0.0, 0.0), (1.0, 2.0, 3.0), (10.0, -5.0, 2.5)],
                            wkt=b'PROJCS["WGS 84 / UTM zone 30N",UNIT["metre",1]]',
                            classes=[2, 6, 11]),
        "georeference/good.json": text(georeference(inliers=12, photos_with_gps=12)),
        "transforms_json/good.json": text(transforms()),
        "annotations/labelme.json": text(labelme([
            {"label": "road", "points": [[0, 0], [30, 0], [30, 20], [0, 20]]},
            {"label": "building", "points": [[40, 10], [60, 40]], "shape_type": "rectangle"}])),
        "annotations/coco.json": text(coco(annotations=[
            {"id": 1, "image_id": 1, "category_id": 1,
             "segmentation": [[0, 0, 30, 0, 30, 20, 0, 20]]},
            {"id": 2, "image_id": 2, "category_id": 3,
             "segmentation": {"size": [H, W], "counts": [100, 200, W * H - 300]}}])),
    }


def write_files(root, files):
    for name, data in sorted(files.items()):
        path = os.path.join(root, name)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as f:
            f.write(data)
    print("%d files in %s" % (len(files), root))


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "regressions":
        write_regressions(sys.argv[2])
    elif len(sys.argv) == 3 and sys.argv[1] == "seeds":
        write_files(sys.argv[2], seeds())
    else:
        sys.exit(__doc__)
