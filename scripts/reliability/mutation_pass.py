"""A mutation pass over sadsplat's readers, through the command line as a user meets them.

Starts from a good input of every reader (scripts/reliability/inputs.py's seeds, the fuzz corpus,
the fixture scene), makes mutated copies (JSON: a value replaced by another type, an extreme
number, a control character, a key removed; binary: header fields set to extreme values, bytes
flipped, the file cut; images: a header claiming a huge size), runs the command that reads each
(`import`, `info`, `train --stream-views` for the scene cache read view by view) and
classifies the outcome:

  ok     exit 0, at most one line on stderr (and, for import, a cache that `info` reads back)
  clean  exit 1 with exactly one line "sadsplat: error: ..." on stderr
  BAD    anything else: another exit status (a crash, "internal error"), more than one line of
         stderr, a timeout (20 s), more than 1 GB of memory, a control byte on the terminal, or
         an import that exits 0 but writes a cache `info` refuses

    python3 scripts/reliability/mutation_pass.py --sadsplat build/bin/sadsplat --out .deps/mutation
        [--per-seed 40] [--jobs 2] [--seed 1] [--only READER]

Prints the table per reader and every BAD input (kept under --out/inputs/). Not part of CI: it
runs for minutes. Standard library only.
"""
import argparse
import concurrent.futures
import json
import os
import random
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import inputs  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FIXTURE = os.path.join(ROOT, "data", "tiny_scene")
MEMORY_LIMIT_KB = 1024 * 1024
TIMEOUT_S = 20

# ---------------------------------------------------------------------------------------------
# Mutators

EXTREME_NUMBERS = [0, -1, 1, 0.5, 1e-300, 5e-324, 1e308, -1e308, 2 ** 31, 2 ** 32, 2 ** 32 + 11,
                   2 ** 53 + 1, 2 ** 63, 2 ** 64, -2 ** 63, 60000, 1e6, 1e7]
ODD_VALUES = [None, True, "", "\u001b[2J", "x" * 5000, [], {}, [[]], [None], {"a": 1}, "nan"]


def json_nodes(value, path=()):
    yield path, value
    if isinstance(value, dict):
        for k, v in value.items():
            yield from json_nodes(v, path + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from json_nodes(v, path + (i,))


def json_set(value, path, new):
    if not path:
        return new
    parent = value
    for p in path[:-1]:
        parent = parent[p]
    parent[path[-1]] = new
    return value


def json_delete(value, path):
    parent = value
    for p in path[:-1]:
        parent = parent[p]
    del parent[path[-1]]
    return value


def mutate_json(data, rng):
    """One structural mutation of a JSON document (bytes -> bytes)."""
    doc = json.loads(data)
    nodes = list(json_nodes(doc))
    path, value = rng.choice(nodes)
    kind = rng.randrange(7)
    if kind == 0 and path:
        json_delete(doc, path)
    elif kind in (1, 2):
        doc = json_set(doc, path, rng.choice(EXTREME_NUMBERS) * rng.choice([1, -1]))
    elif kind == 3:
        doc = json_set(doc, path, rng.choice(ODD_VALUES))
    elif kind == 4 and isinstance(value, list) and value:
        value.extend([value[-1]] * rng.choice([1, 2, 100]))  # duplicates (ids, names)
    else:
        text = json.dumps(doc)
        if rng.random() < 0.5:  # a number beyond double, or a cut-off document
            return text.replace("1", "1e400", 1).encode()
        return text[: rng.randrange(max(1, len(text)))].encode()
    return json.dumps(doc).encode()


def mutate_binary(data, rng, fields=()):
    """Header fields (offset, struct format) set to extreme values, or bytes flipped, or cut."""
    b = bytearray(data)
    kind = rng.randrange(4)
    if kind <= 1 and fields:
        offset, fmt = rng.choice(fields)
        if fmt.endswith("d"):
            value = rng.choice([0.0, -0.0, float("nan"), float("inf"), -float("inf"), 1e308,
                                -1e308, 5e-324, 1e-300])
        else:
            bits = struct.calcsize(fmt) * 8
            value = rng.choice([0, 1, 2 ** bits - 1, 2 ** (bits - 1), 2 ** (bits - 1) - 1,
                                60000]) % (2 ** bits)
            if fmt[-1].islower() and value >= 2 ** (bits - 1):
                value -= 2 ** bits
        struct.pack_into(fmt, b, offset, value)
    elif kind == 2 and b:
        for _ in range(rng.choice([1, 4, 16])):
            i = rng.randrange(len(b))
            b[i] ^= 1 << rng.randrange(8)
    else:
        b = b[: rng.randrange(max(1, len(b)))]
    return bytes(b)


LAS_FIELDS = [(94, "<H"), (96, "<I"), (100, "<I"), (104, "<B"), (105, "<H"), (131, "<d"),
              (139, "<d"), (147, "<d"), (155, "<d"), (163, "<d"), (171, "<d"), (179, "<d"),
              (187, "<d"), (195, "<d"), (203, "<d"), (211, "<d"), (219, "<d"), (247, "<Q")]
PNG_FIELDS = [(16, ">I"), (20, ">I"), (24, ">B"), (25, ">B")]


def mutate_png(data, rng):
    if rng.random() < 0.5:
        w, h = rng.choice([(60000, 60000), (30000, 30000), (1, 1 << 30), (16385, 16385),
                           (64, 1 << 20)])
        return inputs.png(w, h) if rng.random() < 0.5 else inputs.jpeg_claiming(w & 0xffff or 1,
                                                                                h & 0xffff or 1)
    return mutate_binary(data, rng, PNG_FIELDS)


def mutate_sog_meta(data, rng):
    """A .sog with its meta.json mutated (the WebP images kept)."""
    import io
    import zipfile
    src = zipfile.ZipFile(io.BytesIO(data))
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        for name in src.namelist():
            body = src.read(name)
            z.writestr(name, mutate_json(body, rng) if name == "meta.json" else body)
    return out.getvalue()


def fnv1a64(data):
    h = 0xcbf29ce484222325
    for byte in data:
        h = ((h ^ byte) * 0x100000001b3) & 0xffffffffffffffff
    return h


def mutate_cache(data, rng):
    """A scene cache with its payload mutated and its size and checksum made valid again, so that
    the chunk parsers see the mutation (not only the checksum test)."""
    payload = mutate_binary(data[32:], rng, [(i, "<I") for i in range(0, 400, 4)])
    return data[:16] + struct.pack("<QQ", len(payload), fnv1a64(payload)) + payload


def mutate_text_numbers(data, rng):
    """A text file (a COLMAP model) with one number replaced by an extreme value or a word."""
    words = data.split(b" ")
    numeric = [i for i, w in enumerate(words) if w.strip().replace(b".", b"").replace(b"-", b"")
               .isdigit()]
    if not numeric:
        return data
    i = rng.choice(numeric)
    words[i] = rng.choice([b"nan", b"inf", b"1e400", b"-1", b"0", b"4294967307", b"1e308",
                           b"x", b"99999999999999999999"])
    return b" ".join(words)


# ---------------------------------------------------------------------------------------------
# Readers: how a mutated input is placed and which commands read it.


def scene_copy(work, drop=()):
    scene = os.path.join(work, "scene")
    shutil.copytree(FIXTURE, scene)
    for name in drop:
        p = os.path.join(scene, name)
        shutil.rmtree(p) if os.path.isdir(p) else os.remove(p)
    return scene


def place_transforms(work, data):
    scene = scene_copy(work, ["sparse", "split.json"])
    open(os.path.join(scene, "transforms.json"), "wb").write(data)
    return [["import", scene, "--out", os.path.join(work, "s.cache")]]


def place_annotations(work, data):
    scene = scene_copy(work, ["labels", "split.json"])
    path = os.path.join(work, "annotations.json")
    open(path, "wb").write(data)
    return [["import", scene, "--annotations", path, "--out", os.path.join(work, "s.cache")]]


def place_in_scene(relative, drop=()):
    def place(work, data):
        scene = scene_copy(work, drop)
        open(os.path.join(scene, relative), "wb").write(data)
        return [["import", scene, "--out", os.path.join(work, "s.cache")]]
    return place


def place_file(name):
    def place(work, data):
        path = os.path.join(work, name)
        open(path, "wb").write(data)
        return [["info", path]]
    return place


def place_streamed_training(work, data):
    path = os.path.join(work, "m.cache")
    open(path, "wb").write(data)
    return [["train", path, "--stream-views", "--iterations", "2", "--out",
             os.path.join(work, "run")]]


def corpus(path):
    return open(os.path.join(ROOT, "fuzz", "corpus", path), "rb").read()


def interop(path):
    return open(os.path.join(ROOT, "data", "interop", path), "rb").read()


def fixture(path):
    return open(os.path.join(FIXTURE, path), "rb").read()


def readers():
    seeds = inputs.seeds()
    return [
        # name, seed inputs, mutator, placement
        ("transforms.json", [seeds["transforms_json/good.json"]], mutate_json, place_transforms),
        ("LabelMe", [seeds["annotations/labelme.json"]], mutate_json, place_annotations),
        ("COCO", [seeds["annotations/coco.json"]], mutate_json, place_annotations),
        ("georeference.json", [seeds["georeference/good.json"]], mutate_json,
         place_in_scene("georeference.json")),
        ("classes.json", [fixture("classes.json")], mutate_json, place_in_scene("classes.json")),
        ("split.json", [fixture("split.json")], mutate_json, place_in_scene("split.json")),
        ("LAS", [seeds["las/good.las"]], lambda d, r: mutate_binary(d, r, LAS_FIELDS),
         place_file("m.las")),
        ("photo (PNG/JPEG)", [fixture("images/view_000.png")], mutate_png,
         place_in_scene("images/view_000.png")),
        ("label map PNG", [fixture("labels/view_000.png")], mutate_png,
         place_in_scene("labels/view_000.png")),
        ("3DGS PLY", [corpus("gaussian_ply/bin.ply"), corpus("gaussian_ply/ascii.ply")],
         lambda d, r: mutate_binary(d, r), place_file("m.ply")),
        ("SPZ", [corpus("splat_formats/g.spz")], lambda d, r: mutate_binary(d, r),
         place_file("m.spz")),
        ("SOG meta.json", [interop("splat_transform.sog")], mutate_sog_meta, place_file("m.sog")),
        ("SOG bytes", [interop("splat_transform.sog")], lambda d, r: mutate_binary(d, r),
         place_file("m.sog")),
        ("compressed PLY", [interop("splat_transform.compressed.ply")],
         lambda d, r: mutate_binary(d, r), place_file("m.compressed.ply")),
        ("scene cache", [open(FIXTURE + ".cache", "rb").read()], mutate_cache,
         place_file("m.cache")),
        ("COLMAP cameras.txt", [fixture("sparse/0/cameras.txt")], mutate_text_numbers,
         place_in_scene("sparse/0/cameras.txt")),
        ("COLMAP images.txt", [fixture("sparse/0/images.txt")], mutate_text_numbers,
         place_in_scene("sparse/0/images.txt")),
        # The cache read without pixels, its views on loader threads (train --stream-views).
        ("scene cache streamed", [open(FIXTURE + ".cache", "rb").read()], mutate_cache,
         place_streamed_training),
    ]


# ---------------------------------------------------------------------------------------------
# Running and classifying


def run(sadsplat, args, cwd):
    """(exit status, stdout, stderr, peak KiB, seconds); status None = timed out."""
    start = time.time()
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        p = subprocess.Popen([sadsplat] + args, stdout=out, stderr=err, cwd=cwd,
                             start_new_session=True)
        deadline = start + TIMEOUT_S
        status, rss = None, 0
        while True:
            pid, raw, usage = os.wait4(p.pid, os.WNOHANG)
            if pid:
                status = os.waitstatus_to_exitcode(raw)
                rss = usage.ru_maxrss
                break
            if time.time() > deadline:
                os.killpg(p.pid, signal.SIGKILL)
                _, raw, usage = os.wait4(p.pid, 0)
                rss = usage.ru_maxrss
                break
            time.sleep(0.02)
        p.returncode = 0  # reaped above
        out.seek(0)
        err.seek(0)
        return status, out.read(), err.read(), rss, time.time() - start


def classify(sadsplat, reader, place, data, work):
    commands = place(work, data)
    why = []
    outcome = "ok"
    for args in commands:
        status, out, err, rss, seconds = run(sadsplat, args, work)
        lines = [l for l in err.decode("utf-8", "replace").split("\n") if l.strip()]
        if status is None:
            return "BAD", "timeout after %d s: %s" % (TIMEOUT_S, " ".join(args[:1]))
        if rss > MEMORY_LIMIT_KB:
            why.append("%.2f GB" % (rss / 1024 / 1024))
        if b"\x1b" in out or b"\x1b" in err:
            why.append("a control byte on the terminal")
        if status == 0:
            if len(lines) > 1:
                why.append("exit 0 with %d lines on stderr" % len(lines))
        elif status == 1:
            outcome = "clean"
            if len(lines) != 1 or not lines[0].startswith("sadsplat: error:"):
                why.append("exit 1 with %d lines: %s" % (len(lines), " | ".join(lines)[:200]))
        else:
            why.append("exit %s: %s" % (status, " | ".join(lines)[:200]))
        if why:
            return "BAD", "; ".join(why)
        if status != 0:
            return outcome, lines[0][:200]
        if args[0] == "import":  # the cache it wrote must read back
            s2, _, err2, _, _ = run(sadsplat, ["info", args[-1]], work)
            if s2 != 0:
                return "BAD", "import exit 0, its cache refused: " + err2.decode()[:200]
    return outcome, ""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sadsplat", default=os.path.join(ROOT, "build", "bin", "sadsplat"))
    ap.add_argument("--out", default=os.path.join(ROOT, ".deps", "mutation"))
    ap.add_argument("--per-seed", type=int, default=40)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--only", default="", help="run only the readers whose name contains this")
    a = ap.parse_args()
    sadsplat = os.path.abspath(a.sadsplat)
    shutil.rmtree(a.out, ignore_errors=True)
    os.makedirs(os.path.join(a.out, "inputs"))
    rng = random.Random(a.seed)
    jobs = []
    for reader, seeds, mutate, place in readers():
        for s, seed in enumerate(seeds):
            made = set()
            for i in range(a.per_seed):
                data = mutate(seed, rng)  # drawn for every reader: --only keeps the same inputs
                if data in made or a.only not in reader:
                    continue
                made.add(data)
                jobs.append((reader, place, data, "%s_%d_%03d" % (reader.split()[0], s, i)))
    results = {}
    bad = []

    def one(job):
        reader, place, data, name = job
        work = tempfile.mkdtemp(prefix="sadsplat_mutation_")
        try:
            return job, classify(sadsplat, reader, place, data, work)
        finally:
            shutil.rmtree(work, ignore_errors=True)

    start = time.time()
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
        for n, (job, (outcome, detail)) in enumerate(pool.map(one, jobs), 1):
            reader, _, data, name = job
            results.setdefault(reader, {"ok": 0, "clean": 0, "BAD": 0})[outcome] += 1
            if outcome == "BAD":
                path = os.path.join(a.out, "inputs", name)
                open(path, "wb").write(data)
                bad.append((reader, name, detail))
            if n % 50 == 0:
                print("%d/%d inputs, %.0f s" % (n, len(jobs), time.time() - start), flush=True)
    print("\n| reader | inputs | ok | clean error | BAD |\n|---|---:|---:|---:|---:|")
    total = {"ok": 0, "clean": 0, "BAD": 0}
    for reader, r in results.items():
        print("| %s | %d | %d | %d | %d |" % (reader, sum(r.values()), r["ok"], r["clean"],
                                               r["BAD"]))
        for k in total:
            total[k] += r[k]
    print("| all | %d | %d | %d | %d |" % (sum(total.values()), total["ok"], total["clean"],
                                          total["BAD"]))
    for reader, name, detail in bad:
        print("BAD %s %s: %s" % (reader, name, detail))
    print("%.0f s; BAD inputs kept in %s" % (time.time() - start, os.path.join(a.out, "inputs")))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
