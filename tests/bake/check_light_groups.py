#!/usr/bin/env python3
"""Light groups (docs/light-groups.md): a lightmap per group, the bake's lightmap their sum.

usage: check_light_groups.py LMBAKE WORKDIR [short]   (short, the sanitizer pass: scales (0.3, 2)
       only, no plain bakes, no --threads runs, the sun off and lamp_a dimmed left out (the sun's
       edit and lamp_b moved read back and relight the same way), no random lights, no bake
       with the groups' light in memory, one_per_light without its byte comparisons, no sky or
       emissive groups: the same code, a third of the bakes)

The level: sun-lamps.gltf (tools/make_scenes.py: a 10 x 10 ground, a closed 1 m cube on it, a sun
of 1000 lux, two coloured point lamps: lamp_a 200 cd, lamp_b 100 cd), baked at 6 texels per unit with output.light_groups {sun: match sun} and {lamps: match lamp_*}.
  - engine sum: a game's sum of the two groups' files (32-bit float EXR) of the bake at scales
    (1, 1), at weights (1, 0), (0, 1) and (0.3, 2), each times the group's intensity (RGB, named
    in the glTF: the sun's, alone in its group, is its intensity x colour and its files hold it at
    1; the lamps' 1 1 1), equals the lightmap of a bake whose groups have those scales, within
    1e-6 relative at every texel above 1e-6 of the brightest;
  - the light probes likewise: their SH and ambient cubes = sum_g w_g x intensity_g x each group's
    own (named in asset.extras.lightmap.probes.groups), within 1e-6 relative; and bevy's volume =
    sum_g w_g x intensity_g x each group's own volume (extras.lightmap.irradianceVolume.groups),
    read with tests/ktx2/read_ktx2.mjs, within E5B9G9R9's rounding;
  - the groups' files are the same bytes whatever the scales (no group reads a scale), and the
    same at 1 and 3 threads, from a farm of 2 shards, and with each group's light kept in memory
    (no TMPDIR folder: said once) instead of in its file (every output file byte for byte);
  - the sum at (1, 1) is the level's light: against a bake without groups, the mean within 1% and
    the per-texel rms difference within 1.5x that between two seeds of the plain bake (+0.2%);
  - the glTF names each group's name, scale, intensity and files on every lightmap texture and node;
  - kept between bakes (--layout-cache, the watch's): a bake at new scales reads every group back and
    writes the bytes of a bake without the cache; so does an edit of the sun's intensity and colour
    (alone in its group: its weight), the sun switched off, sky.intensity with the sky alone in
    its group, and an emissive material's strength and colour with the emissive surfaces alone in
    theirs; random intensities and colours of every light, each alone in its group; an edit or a move of a lamp lights the lamps' group again and reads the sun's
    back; every time the bytes of a bake without it;
  - a light's extras.lightmap_group makes a group of its own, the rest go to 'rest';
  - one_per_light: a group per light named after it, the bytes of the same groups named in the
    config; with 11 lights (8 torches of 5-40 cd added) the sun, the lamps and the 4 brightest
    torches get their own, the 4 dimmest share 'rest' and the log names them; with a sky and
    the level's material glowing too (106 pi S of power at emissive strength S), the surfaces
    take torch_5's group at S = 1.16 and share 'rest' at 1.10 (torch_5's power 120 pi: S = 1.132);
    on the 3-light level with both, groups sun,
    lamp_a, lamp_b, sky, emissive (their weights the sky's intensity and the emission), every file
    the bytes of those five groups named in the config;
  - bad input exits 2 with nothing written: a group that holds no light (its config line named),
    a name that cannot name a file, 9 groups, an extras.lightmap_group that is not a string,
    one_per_light with a name, one_per_light matching no light.
"""
import filecmp
import json
import os
import re
import shutil
import struct
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
fails = []


def check(ok, what):
    print("%s %s" % ("ok  " if ok else "FAIL", what))
    if not ok:
        fails.append(what)


def read_exr(path):
    i = oiio.ImageInput.open(path)
    if not i:
        raise RuntimeError("cannot open %s" % path)
    a = i.read_image(format="float")
    i.close()
    return np.asarray(a, dtype=np.float64)


def probe_floats(gltf, view):
    """A buffer view of float32 (the probes' SH or ambient cubes) as a numpy array."""
    with open(gltf) as f:
        doc = json.load(f)
    v = doc["bufferViews"][view]
    with open(os.path.join(os.path.dirname(gltf), doc["buffers"][v["buffer"]]["uri"]), "rb") as f:
        f.seek(v.get("byteOffset", 0))
        data = f.read(v["byteLength"])
    return np.array(struct.unpack("<%df" % (len(data) // 4), data), dtype=np.float64)


def probes_of(gltf):
    """asset.extras.lightmap.probes: (sum's sh, sum's cube, {group: (scale, sh, cube)}), each group's
    sh and cube times its intensity (RGB, channel k % 3), as a game reads them."""
    with open(gltf) as f:
        p = json.load(f)["asset"]["extras"]["lightmap"]["probes"]

    def lit(g, key):
        v = probe_floats(gltf, g[key])
        return v * np.tile(np.array(g["intensity"], dtype=np.float64), len(v) // 3)
    groups = {g["name"]: (g["scale"], lit(g, "sh"), lit(g, "ambientCube")) for g in p.get("groups", [])}
    return probe_floats(gltf, p["sh"]), probe_floats(gltf, p["ambientCube"]), groups


def group_intensities(gltf):
    """{group: its intensity (RGB) as the lightmap texture's extras.lightmap.groups name it}."""
    with open(gltf) as f:
        doc = json.load(f)
    tex = next(t for t in doc["textures"] if t.get("extras", {}).get("lightmap", {}).get("groups"))
    return {g["name"]: np.array(g["intensity"], dtype=np.float64) for g in tex["extras"]["lightmap"]["groups"]}


def group_intensities_list(gltf):
    """The groups as the lightmap texture's extras.lightmap.groups lists them, in order."""
    with open(gltf) as f:
        doc = json.load(f)
    tex = next(t for t in doc["textures"] if t.get("extras", {}).get("lightmap", {}).get("groups"))
    return tex["extras"]["lightmap"]["groups"]


def group_light(out, stem, group):
    """A group's light as a game reads it: its EXR times its intensity."""
    return read_exr(os.path.join(out, "%s-lightmap-0-group-%s.exr" % (stem, group)))[..., :3] * \
        group_intensities(os.path.join(out, stem + ".gltf"))[group]


def bake(lmbake, work, scene, name, config, *args, env=None):
    """lmbake bake, quiet unless args say --log (then its log lines: no progress, every info line)."""
    cfg = os.path.join(work, name + ".yaml")
    with open(cfg, "w") as f:
        f.write(config)
    out = os.path.join(work, name)
    shutil.rmtree(out, ignore_errors=True)
    quiet = [] if "--log" in args else ["-q"]
    args = [a for a in args if a != "--log"]
    p = subprocess.run([lmbake, "bake", scene, "-c", cfg, "-o", out] + quiet + args, capture_output=True, text=True,
                       env=env)
    return out, p


def make_level(work):
    scenes = os.path.join(work, "scenes")
    subprocess.run([sys.executable, os.path.join(ROOT, "tools", "make_scenes.py"), scenes], check=True,
                   stdout=subprocess.DEVNULL)
    level = os.path.join(scenes, "sun-lamps.gltf")
    with open(level) as f:
        return scenes, level, json.load(f)


BASE = "texel_density: 6\n"


def groups_config(sun, lamps):
    return BASE + "output:\n  light_groups:\n    - {name: sun, match: sun, scale: %r}\n" \
                  "    - {name: lamps, match: \"lamp_*\", scale: %r}\n" % (sun, lamps)


def group_files(out):
    return sorted(f for f in os.listdir(out) if re.search(r"-lightmap-\d+-group-", f))


def engine(lmbake, work, level, short):
    ref, p = bake(lmbake, work, level, "scales-1-1", groups_config(1.0, 1.0))
    check(p.returncode == 0, "bake with groups sun and lamps: exit %d %s" % (p.returncode, p.stderr[-400:]))
    if p.returncode:
        return
    files = group_files(ref)
    check(files == ["sun-lamps-lightmap-0-group-lamps.exr", "sun-lamps-lightmap-0-group-lamps.hdr",
                    "sun-lamps-lightmap-0-group-sun.exr", "sun-lamps-lightmap-0-group-sun.hdr"],
          "each group's lightmap written: %s" % files)
    sun, lamps = (group_light(ref, "sun-lamps", g) for g in ("sun", "lamps"))
    for ws in ((0.3, 2.0),) if short else ((1.0, 0.0), (0.0, 1.0), (0.3, 2.0)):
        out, p = bake(lmbake, work, level, "scales-%g-%g" % ws, groups_config(*ws))
        if p.returncode:
            check(False, "bake at scales %s: exit %d %s" % (ws, p.returncode, p.stderr[-400:]))
            continue
        same = all(filecmp.cmp(os.path.join(ref, f), os.path.join(out, f), shallow=False) for f in files)
        baked = read_exr(os.path.join(out, "sun-lamps-lightmap-0.exr"))[..., :3]
        summed = ws[0] * sun + ws[1] * lamps
        lit = baked > 1e-6 * max(baked.max(), 1e-30)
        rel = np.abs(summed - baked)[lit] / baked[lit] if lit.any() else np.array([np.inf])
        check(same and lit.sum() > 1000 and rel.max() <= 1e-6,
              "scales %s: the engine's sum of the groups' EXRs = the bake's lightmap, worst %.2e relative over %d "
              "channels (bound 1e-6); the groups' files %s" % (ws, rel.max(), lit.sum(),
                                                              "the same bytes" if same else "DIFFER"))
        # the probes likewise: the sum's SH and ambient cubes = sum_g w_g x the groups' (of the (1, 1) bake)
        sh, cube, pg = probes_of(os.path.join(out, "sun-lamps.gltf"))
        sh1, cube1, pg1 = probes_of(os.path.join(ref, "sun-lamps.gltf"))
        worst, same_groups = 0.0, sorted(pg) == ["lamps", "sun"] and sorted(pg1) == ["lamps", "sun"]
        for total, k in ((sh, 1), (cube, 2)):
            summed = ws[0] * pg1["sun"][k] + ws[1] * pg1["lamps"][k] if same_groups else total * 0
            big = np.abs(total) > 1e-6 * np.abs(total).max()
            worst = max(worst, (np.abs(summed - total)[big] / np.abs(total)[big]).max())
            same_groups = same_groups and all(np.array_equal(pg[g][k], pg1[g][k]) for g in pg1)
        check(same_groups and worst <= 1e-6 and [pg[g][0] for g in ("sun", "lamps")] == list(ws),
              "scales %s: the probes' SH and ambient cubes = sum_g w_g x the groups' (asset.extras.lightmap.probes."
              "groups), worst %.2e relative (bound 1e-6); the groups' probes the same at every scale: %s"
              % (ws, worst, same_groups))
        volumes_sum(work, ref, out, ws)
    if not short:
        plain_against(lmbake, work, level, sun, lamps)
    gltf_names(ref, level)
    threads_and_farm(lmbake, work, level, ref, short)


def read_volume(work, path):
    """A bevy volume's texels (float32 RGB) through the independent reader (tests/ktx2/read_ktx2.mjs)."""
    f32 = os.path.join(work, "volume.f32")
    p = subprocess.run(["node", os.path.join(ROOT, "tests", "ktx2", "read_ktx2.mjs"), path, f32], capture_output=True,
                       text=True, cwd=ROOT)
    if p.returncode:
        return None
    return np.fromfile(f32, dtype="<f4").reshape(-1, 3).astype(np.float64)


def volumes_sum(work, ref, out, ws):
    """Each group's own bevy volume (named in the volume node's extras.lightmap.irradianceVolume.groups):
    sum_g w_g x intensity_g x volume_g = the volume of the bake at scales ws, within E5B9G9R9's
    rounding (2^-9 of each texel's largest channel, in every term)."""
    def volume_of(folder):
        with open(os.path.join(folder, "sun-lamps.gltf")) as f:
            doc = json.load(f)
        return next(n["extras"]["lightmap"]["irradianceVolume"] for n in doc["nodes"]
                    if "irradianceVolume" in n.get("extras", {}).get("lightmap", {}))
    v_ref, v_out = volume_of(ref), volume_of(out)
    groups = {g["name"]: g for g in v_ref.get("groups", [])}
    level = read_volume(work, os.path.join(out, v_out["uri"]))
    parts = {n: read_volume(work, os.path.join(ref, g["uri"])) for n, g in groups.items()}
    if sorted(groups) != ["lamps", "sun"] or level is None or any(v is None for v in parts.values()):
        check(False, "scales %s: each group's bevy volume named and read (%s)" % (ws, sorted(groups)))
        return
    summed, tol = np.zeros_like(level), 2.0 ** -9 * level.max(axis=1, keepdims=True)
    for w, n in zip(ws, ("sun", "lamps")):
        term = w * np.array(groups[n]["intensity"]) * parts[n]
        summed += term
        tol += 2.0 ** -9 * term.max(axis=1, keepdims=True)
    worst = float(np.max(np.abs(summed - level) / (tol + 1e-9)))
    check(worst <= 1.0 and level.max() > 0,
          "scales %s: the engine's sum of the groups' bevy volumes (%d texels) = the bake's volume, worst %.2f of "
          "E5B9G9R9's rounding" % (ws, level.shape[0], worst))


def plain_against(lmbake, work, level, sun, lamps):
    """The sum at (1, 1) against a bake without groups, and that bake's own noise (two seeds)."""
    plain, p1 = bake(lmbake, work, level, "plain", BASE)
    plain2, p2 = bake(lmbake, work, level, "plain-seed2", BASE + "seed: 2\n")
    if p1.returncode or p2.returncode:
        check(False, "plain bakes: exit %d, %d" % (p1.returncode, p2.returncode))
        return
    a, b = (read_exr(os.path.join(d, "sun-lamps-lightmap-0.exr"))[..., :3] for d in (plain, plain2))
    s = sun + lamps
    lit = a > 0.01 * a.max()
    diff = np.sqrt(np.mean(((s - a)[lit] / a[lit]) ** 2))
    noise = np.sqrt(np.mean(((b - a)[lit] / a[lit]) ** 2))
    ratio = s[lit].mean() / a[lit].mean()
    check(abs(ratio - 1) <= 0.01 and diff <= 1.5 * noise + 0.002,
          "sun + lamps = the bake without groups: mean ratio %.4f, %.2f%% rms per texel (two seeds of the plain bake: "
          "%.2f%% rms)" % (ratio, 100 * diff, 100 * noise))
    lamp_share = lamps[lit].mean() / s[lit].mean()
    check(0.001 < lamp_share < 0.5, "the lamps' group holds their light: %.2f%% of the level's" % (100 * lamp_share))


def gltf_names(ref, level):
    with open(os.path.join(ref, "sun-lamps.gltf")) as f:
        doc = json.load(f)
    with open(level) as f:
        sun = next(l for l in json.load(f)["extensions"]["KHR_lights_punctual"]["lights"] if l["name"] == "sun")
    named = [t["extras"]["lightmap"].get("groups") for t in doc["textures"]
             if "lightmap" in t.get("extras", {}) and "files" in t["extras"]["lightmap"]]
    # the sun alone in its group: its files hold it at intensity 1, the glTF names its intensity x colour
    want = [{"name": "sun", "scale": 1.0, "intensity": [sun["intensity"] * c for c in sun.get("color", [1, 1, 1])],
             "files": {"exr": "sun-lamps-lightmap-0-group-sun.exr", "hdr": "sun-lamps-lightmap-0-group-sun.hdr"}},
            {"name": "lamps", "scale": 1.0, "intensity": [1.0, 1.0, 1.0],
             "files": {"exr": "sun-lamps-lightmap-0-group-lamps.exr", "hdr": "sun-lamps-lightmap-0-group-lamps.hdr"}}]
    nodes = [n["extras"]["lightmap"].get("groups") for n in doc["nodes"]
             if "atlas" in n.get("extras", {}).get("lightmap", {})]
    check(named == [want] and nodes and all(g == want for g in nodes),
          "extras.lightmap.groups on the lightmap texture and its %d nodes: %s" % (len(nodes), json.dumps(named)[:300]))


def threads_and_farm(lmbake, work, level, ref, short):
    t3, p = bake(lmbake, work, level, "threads-3", groups_config(1.0, 1.0), "--threads", "3") if not short else (None, None)
    # at 1 thread with TMPDIR at a missing folder: each group's light, which waits for the files
    # in a file in TMPDIR, stays in memory where no file can be made (said once), the same bytes
    t1, p1 = bake(lmbake, work, level, "threads-1", groups_config(1.0, 1.0), "--threads", "1", "--log",
                  env=dict(os.environ, TMPDIR=os.path.join(work, "no-such-folder"))) if not short else (None, None)
    farm_out = os.path.join(work, "farm-out")
    shutil.rmtree(farm_out, ignore_errors=True)
    shutil.rmtree(os.path.join(work, "farm"), ignore_errors=True)
    pf = subprocess.run([lmbake, "farm", "parallel", level, "-c", os.path.join(work, "scales-1-1.yaml"), "--farm",
                         os.path.join(work, "farm"), "-o", farm_out, "--shards", "2", "--threads", "1", "-q"],
                        capture_output=True, text=True)
    runs = [("farm parallel, 2 shards", farm_out, pf.returncode)]
    if short:
        return check_runs(ref, runs)
    said = [l for l in p1.stderr.splitlines() if "stays in memory" in l]
    check(p1.returncode == 0 and len(said) == 1 and "no-such-folder" in said[0],
          "TMPDIR without a folder: the groups' light kept in memory, said once: %s" % (said or p1.stderr[-300:]))
    runs += [("--threads 3", t3, p.returncode), ("--threads 1, the groups' light in memory", t1, p1.returncode)]
    check_runs(ref, runs)


def check_runs(ref, runs):
    """Every run's files the bytes of ref's."""
    for name, out, rc in runs:
        listed = sorted(os.listdir(ref))
        differ = [f for f in listed if rc == 0 and (not os.path.exists(os.path.join(out, f)) or
                                                   not filecmp.cmp(os.path.join(ref, f), os.path.join(out, f), shallow=False))]
        check(rc == 0 and not differ and sorted(os.listdir(out)) == listed,
              "%s: every one of %d files the same bytes%s" % (name, len(listed), " (differ: %s)" % differ if differ else ""))


def kept_between_bakes(lmbake, work, level, doc, short):
    """--layout-cache (the watch's): a scale edit reads every group back, the files those of a bake
    without the cache; an edit of the glTF lights them again."""
    cache = os.path.join(work, "kept")
    shutil.rmtree(cache, ignore_errors=True)
    first, p1 = bake(lmbake, work, level, "kept-1-1", groups_config(1.0, 1.0), "--layout-cache", cache, "--log")
    again, p2 = bake(lmbake, work, level, "kept-0.3-2", groups_config(0.3, 2.0), "--layout-cache", cache, "--log")
    fresh = os.path.join(work, "scales-0.3-2")
    listed = sorted(os.listdir(fresh)) if os.path.isdir(fresh) else []
    differ = [f for f in listed if p2.returncode == 0 and (not os.path.exists(os.path.join(again, f)) or
                                                          not filecmp.cmp(os.path.join(fresh, f), os.path.join(again, f),
                                                                          shallow=False))]
    log = p2.stdout + p2.stderr
    read_back = log.count("read back from the cache")
    check(p1.returncode == 0 and p2.returncode == 0 and read_back == 2 and "): lighting" not in log and listed
          and not differ and sorted(os.listdir(again)) == listed,
          "scales (1, 1) then (0.3, 2) with --layout-cache: %d of 2 groups read back, none lit; every one of %d files "
          "the bytes of a bake without the cache%s" % (read_back, len(listed), " (differ: %s)" % differ if differ else ""))
    # each group's own files kept too (copied, not encoded again); a damaged one is encoded again
    kept_files = sorted(f for f in os.listdir(cache) if f.endswith("-a0.lmbf")) if os.path.isdir(cache) else []
    check(len(kept_files) == 2, "each group's own files kept beside its light: %s" % kept_files)
    # --relight-only: with everything kept the bake of other scales runs; with a group not kept it
    # stops (exit 4) and writes nothing
    relit, pr = bake(lmbake, work, level, "relight-only", groups_config(0.5, 1.5), "--layout-cache", cache,
                     "--relight-only")
    d = json.loads(json.dumps(doc))
    d["extensions"]["KHR_lights_punctual"]["lights"][1]["intensity"] *= 0.5
    dimmed = os.path.join(os.path.dirname(level), "sun-lamps-relight-only.gltf")
    with open(dimmed, "w") as f:
        json.dump(d, f)
    refused, pn = bake(lmbake, work, dimmed, "relight-refused", groups_config(0.5, 1.5), "--layout-cache", cache,
                       "--relight-only")
    check(pr.returncode == 0 and os.path.isdir(relit) and pn.returncode == 4 and not os.path.exists(refused)
          and "light group 'lamps' is to be lit" in pn.stderr,
          "--relight-only: other scales bake (exit %d); a lamp dimmed in a shared group: exit %d, nothing written, %r"
          % (pr.returncode, pn.returncode, pn.stderr.strip()[-120:]))
    for f in kept_files:
        path = os.path.join(cache, f)
        data = bytearray(open(path, "rb").read())
        data[len(data) // 2] ^= 0xFF
        open(path, "wb").write(data)
    damaged, p4 = bake(lmbake, work, level, "kept-damaged", groups_config(0.3, 2.0), "--layout-cache", cache, "--log")
    log = p4.stdout + p4.stderr
    differ = [f for f in listed if p4.returncode == 0 and (not os.path.exists(os.path.join(damaged, f)) or
                                                          not filecmp.cmp(os.path.join(fresh, f), os.path.join(damaged, f),
                                                                          shallow=False))]
    check(p4.returncode == 0 and log.count("encoding the group's files instead") == 2 and listed and not differ,
          "the kept files damaged: said, encoded again, every file still the bytes of a bake without the cache%s"
          % (" (differ: %s)" % differ if differ else ""))
    # edits of the glTF's lights: the sun is alone in its group (lit at unit intensity and white,
    # weighed by its intensity x colour), the lamps share theirs
    lights = doc["extensions"]["KHR_lights_punctual"]["lights"]
    sun = next(i for i, l in enumerate(lights) if l["name"] == "sun")
    lamp_a = next(i for i, l in enumerate(lights) if l["name"] == "lamp_a")

    def edited_bake(name, what, edit, lit, read):
        d = json.loads(json.dumps(doc))
        edit(d)
        edited = os.path.join(os.path.dirname(level), "sun-lamps-%s.gltf" % name)
        with open(edited, "w") as f:
            json.dump(d, f)
        out, p = bake(lmbake, work, edited, "kept-" + name, groups_config(0.3, 2.0), "--layout-cache", cache, "--log")
        plain, pp = bake(lmbake, work, edited, "plain-" + name, groups_config(0.3, 2.0))
        log = p.stdout + p.stderr
        names = sorted(os.listdir(plain)) if pp.returncode == 0 else []
        differ = [f for f in names if p.returncode != 0 or not os.path.exists(os.path.join(out, f)) or
                  not filecmp.cmp(os.path.join(plain, f), os.path.join(out, f), shallow=False)]
        check(p.returncode == 0 and log.count("): lighting") == lit and log.count("read back from the cache") == read
              and names and not differ,
              "%s: %d group(s) lit again, %d read back (want %d, %d); every one of %d files the bytes of a bake "
              "without the cache%s" % (what, log.count("): lighting"), log.count("read back from the cache"), lit, read,
                                       len(names), " (differ: %s)" % differ if differ else ""))
        return out

    def brighter_warmer_sun(d):
        d["extensions"]["KHR_lights_punctual"]["lights"][sun]["intensity"] *= 2.5
        d["extensions"]["KHR_lights_punctual"]["lights"][sun]["color"] = [1.0, 0.85, 0.7]
    tinted = edited_bake("sun-tinted", "the sun x 2.5 and tinted in the glTF (alone in its group)", brighter_warmer_sun, 0, 2)
    # the sun's own files hold its light at intensity 1: the same bytes before and after the edit,
    # the glTF's intensity the new one
    same = all(filecmp.cmp(os.path.join(first, "sun-lamps-lightmap-0-group-sun.%s" % e),
                           os.path.join(tinted, "sun-lamps-sun-tinted-lightmap-0-group-sun.%s" % e), shallow=False)
               for e in ("exr", "hdr")) if os.path.isdir(tinted) else False
    got = group_intensities(os.path.join(tinted, "sun-lamps-sun-tinted.gltf"))["sun"].tolist() if same else None
    want = [lights[sun]["intensity"] * 2.5 * c for c in (1.0, 0.85, 0.7)]
    check(same and np.allclose(got, want, rtol=1e-6),  # the colour as a float
          "the sun's own EXR and HDR the same bytes after its edit; the glTF names its new intensity %s (want %s)"
          % (got, want))

    def sun_off(d):
        d["extensions"]["KHR_lights_punctual"]["lights"][sun]["intensity"] = 0.0
    if not short:  # the same read-back as the sun's edit above; Release only
        edited_bake("sun-off", "the sun switched off (intensity 0)", sun_off, 0, 2)

    def dim_lamp_a(d):
        d["extensions"]["KHR_lights_punctual"]["lights"][lamp_a]["intensity"] = 150.0
    if not short:  # the same relighting of one group as lamp_b moved below; Release only
        edited_bake("lamp-a-150", "lamp_a 200 -> 150 cd (its group holds lamp_b too)", dim_lamp_a, 1, 1)

    def move_lamp_b(d):
        lamp_b = next(i for i, l in enumerate(lights) if l["name"] == "lamp_b")
        node = next(n for n in d["nodes"] if n.get("extensions", {}).get("KHR_lights_punctual", {}).get("light") == lamp_b)
        node["translation"] = [t + 0.5 for t in node.get("translation", [0, 0, 0])]
        node["name"] = "lamp_b moved"
    edited_bake("lamp-b-moved", "lamp_b moved 0.5 m on each axis", move_lamp_b, 1, 1)

    if short:  # the sky's and the emissive surfaces' weights: Release only (the sanitizers' pass
        return     # reads a unit group back and copies its files in the sun's edit above)
    # the config's sky alone in its group: a unit group too, sky.intensity x sky.color its weight
    # (no ground colour: the sky is lit at 1 and white)
    def sky_groups(intensity, color):
        return BASE + "sky: {intensity: %r, color: %r}\noutput:\n  light_groups:\n    - {name: sky, sky: true}\n" \
                      "    - {name: lights, match: \"*\"}\n" % (intensity, color)
    sky_cache = os.path.join(work, "kept-sky")
    shutil.rmtree(sky_cache, ignore_errors=True)
    first_out, s1 = bake(lmbake, work, level, "sky-400-kept", sky_groups(400.0, [1.0, 1.0, 1.0]), "--layout-cache",
                         sky_cache, "--log")
    tint = [1.0, 0.8, 0.6]
    kept_out, s2 = bake(lmbake, work, level, "sky-150-kept", sky_groups(150.0, tint), "--layout-cache", sky_cache,
                        "--log")
    fresh_out, s3 = bake(lmbake, work, level, "sky-150", sky_groups(150.0, tint))
    log1, log2 = s1.stdout + s1.stderr, s2.stdout + s2.stderr
    names = sorted(os.listdir(fresh_out)) if s3.returncode == 0 else []
    differ = [f for f in names if s2.returncode != 0 or not os.path.exists(os.path.join(kept_out, f)) or
              not filecmp.cmp(os.path.join(fresh_out, f), os.path.join(kept_out, f), shallow=False)]
    own = [f for f in names if "-group-sky." in f]
    moved = [f for f in own if s1.returncode != 0 or
             not filecmp.cmp(os.path.join(first_out, f), os.path.join(fresh_out, f), shallow=False)]
    named = [list(group_intensities(os.path.join(fresh_out, "sun-lamps.gltf"))["sky"])] if s3.returncode == 0 else []
    want = [150.0 * c for c in tint]
    check(s1.returncode == 0 and "weighed by sky.intensity x sky.color: [400, 400, 400]" in log1 and
          s2.returncode == 0 and log2.count("read back from the cache") == 2 and "): lighting" not in log2 and
          names and not differ and own and not moved and len(named) == 1 and
          all(abs(a - b) <= 1e-6 * b for a, b in zip(named[0], want)),
          "sky.intensity 400 -> 150 and sky.color white -> %s (the sky alone in its group): both groups read back; "
          "every one of %d files the bytes of a bake without the cache%s; the sky's own files (%d) the bytes of the "
          "first bake's%s; the glTF names its intensity %s (want %s)"
          % (tint, len(names), " (differ: %s)" % differ if differ else "", len(own),
             " (differ: %s)" % moved if moved else "", named, want))
    if not short:
        # under a ground colour the sky's colour is not a weight (the ground is not tinted by it,
        # and the two colours' ratio decides where samples go): a tint lights the sky's group again
        def grounded(color):
            return BASE + "sky: {intensity: 400.0, color: %r, ground_color: [0.3, 0.25, 0.2]}\noutput:\n" \
                          "  light_groups:\n    - {name: sky, sky: true}\n    - {name: lights, match: \"*\"}\n" % color
        ground_cache = os.path.join(work, "kept-ground")
        shutil.rmtree(ground_cache, ignore_errors=True)
        _, g1 = bake(lmbake, work, level, "ground-white-kept", grounded([1.0, 1.0, 1.0]), "--layout-cache",
                     ground_cache, "--log")
        _, g2 = bake(lmbake, work, level, "ground-tinted-kept", grounded(tint), "--layout-cache", ground_cache, "--log")
        log1, log2 = g1.stdout + g1.stderr, g2.stdout + g2.stderr
        check(g1.returncode == 0 and "weighed by sky.intensity: [400, 400, 400]" in log1 and g2.returncode == 0 and
              "light group 'sky' (1 of 2): lighting" in log2 and log2.count("read back from the cache") == 1,
              "with a ground colour the sky's weight is its intensity alone, and a tint lights its group again (the "
              "other read back): %s" % ("yes" if g2.returncode == 0 and "light group 'sky' (1 of 2): lighting" in log2
                                        else (log1 + log2)[-300:]))

    # the emissive surfaces alone in their group (one emissive material: its emission the weight)
    def glowing(factor, strength):
        d = json.loads(json.dumps(doc))
        d["materials"].append({"name": "glow", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0]},
                               "emissiveFactor": factor,
                               "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}})
        d.setdefault("extensionsUsed", []).append("KHR_materials_emissive_strength")
        cube = next(n["mesh"] for n in d["nodes"] if n.get("name") == "cube")
        for prim in d["meshes"][cube]["primitives"]:
            prim["material"] = len(d["materials"]) - 1
        path = os.path.join(os.path.dirname(level), "sun-lamps-glow-%g.gltf" % strength)
        with open(path, "w") as f:
            json.dump(d, f)
        return path
    glow_cfg = BASE + "output:\n  light_groups:\n    - {name: glow, emissive: true}\n    - {name: lights, match: \"*\"}\n"
    glow_cache = os.path.join(work, "kept-glow")
    shutil.rmtree(glow_cache, ignore_errors=True)
    first_level, edited_level = glowing([1.0, 0.9, 0.8], 4.0), glowing([0.6, 0.8, 1.0], 12.0)
    _, e1 = bake(lmbake, work, first_level, "glow-kept", glow_cfg, "--layout-cache", glow_cache, "--log")
    kept_out, e2 = bake(lmbake, work, edited_level, "glow-tinted-kept", glow_cfg, "--layout-cache", glow_cache, "--log")
    fresh_out, e3 = bake(lmbake, work, edited_level, "glow-tinted", glow_cfg)
    log1, log2 = e1.stdout + e1.stderr, e2.stdout + e2.stderr
    names = sorted(os.listdir(fresh_out)) if e3.returncode == 0 else []
    differ = [f for f in names if e2.returncode != 0 or not os.path.exists(os.path.join(kept_out, f)) or
              not filecmp.cmp(os.path.join(fresh_out, f), os.path.join(kept_out, f), shallow=False)]
    glow_exr = [f for f in names if f.endswith("-group-glow.exr")]
    bright = glow_exr and read_exr(os.path.join(fresh_out, glow_exr[0])).max() > 0
    check(e1.returncode == 0 and "weighed by the surfaces' emissive colour x strength" in log1 and e2.returncode == 0
          and log2.count("read back from the cache") == 2 and "): lighting" not in log2 and names and not differ
          and bright,
          "an emissive cube's strength 4 -> 12 and tinted (alone in its group): both groups read back; every one of "
          "%d files the bytes of a bake without the cache%s" % (len(names), " (differ: %s)" % differ if differ else ""))
    # lit at emission 1 and weighed: the light of a bake of the emission alone (the lights off)
    only_out, e4 = bake(lmbake, work, edited_level, "glow-only", BASE + "lights: {intensity_scale: 0}\n")
    only_exr = [f for f in os.listdir(only_out) if f.endswith("-lightmap-0.exr")] if e4.returncode == 0 else []
    if glow_exr and only_exr:
        weighed = group_light(fresh_out, glow_exr[0][:-len("-lightmap-0-group-glow.exr")], "glow").sum(axis=(0, 1))
        alone = read_exr(os.path.join(only_out, only_exr[0]))[..., :3].sum(axis=(0, 1))
        ratio = weighed / np.maximum(alone, 1e-30)
    else:
        ratio = np.zeros(3)
    check(np.all(np.abs(ratio - 1) < 0.01),
          "the emissive group weighed by its emission = a bake of the emission alone: per-channel sums' ratio %s "
          "(bound 1%%)" % np.round(ratio, 5).tolist())


def random_lights(lmbake, work, level, doc, short):
    """Every light alone in its group (a unit group each): for random intensities and colours of
    every light, a bake that reads the groups back writes the bytes of a bake of the level with
    those values."""
    import random
    rng = random.Random(62)
    cfg = BASE + "output:\n  light_groups:\n" + "".join(
        "    - {name: %s, match: %s}\n" % (l["name"], l["name"]) for l in doc["extensions"]["KHR_lights_punctual"]["lights"])
    cache = os.path.join(work, "kept-random")
    shutil.rmtree(cache, ignore_errors=True)
    _, p0 = bake(lmbake, work, level, "random-kept", cfg, "--layout-cache", cache)
    ok = p0.returncode == 0
    tried = []
    for k in range(1 if short else 2):
        d = json.loads(json.dumps(doc))
        for l in d["extensions"]["KHR_lights_punctual"]["lights"]:
            l["intensity"] = l["intensity"] * rng.uniform(0.0, 3.0)
            l["color"] = [round(rng.uniform(0.0, 1.0), 4) for _ in range(3)]
        edited = os.path.join(os.path.dirname(level), "sun-lamps-random-%d.gltf" % k)
        with open(edited, "w") as f:
            json.dump(d, f)
        out, p = bake(lmbake, work, edited, "random-%d-kept" % k, cfg, "--layout-cache", cache, "--log")
        plain, pp = bake(lmbake, work, edited, "random-%d" % k, cfg)
        log = p.stdout + p.stderr
        names = sorted(os.listdir(plain)) if pp.returncode == 0 else []
        differ = [f for f in names if p.returncode != 0 or not os.path.exists(os.path.join(out, f)) or
                  not filecmp.cmp(os.path.join(plain, f), os.path.join(out, f), shallow=False)]
        ok &= p.returncode == 0 and log.count("read back from the cache") == 3 and "): lighting" not in log and \
            bool(names) and not differ
        tried.append("%d files%s" % (len(names), " (differ: %s)" % differ if differ else ""))
    check(ok, "every light alone in its group, random intensities and colours %s: all 3 groups read back, the "
          "bytes of a bake of the edited level (%s)" % ("once" if short else "twice", "; ".join(tried)))


def extras_group(lmbake, work, level, doc):
    d = json.loads(json.dumps(doc))
    d["extensions"]["KHR_lights_punctual"]["lights"][1]["extras"] = {"lightmap_group": "torch"}
    path = os.path.join(os.path.dirname(level), "extras-group.gltf")
    with open(path, "w") as f:
        json.dump(d, f)
    out, p = bake(lmbake, work, path, "extras-group", BASE)
    files = group_files(out) if p.returncode == 0 else []
    check(p.returncode == 0 and
          files == ["extras-group-lightmap-0-group-rest.exr", "extras-group-lightmap-0-group-rest.hdr",
                    "extras-group-lightmap-0-group-torch.exr", "extras-group-lightmap-0-group-torch.hdr"],
          "a light's extras.lightmap_group 'torch' and no config: groups torch and rest (%s)" % files)
    d["extensions"]["KHR_lights_punctual"]["lights"][1]["extras"] = {"lightmap_group": 3}
    path = os.path.join(os.path.dirname(level), "extras-bad.gltf")
    with open(path, "w") as f:
        json.dump(d, f)
    out, p = bake(lmbake, work, path, "extras-bad", BASE)
    check(p.returncode == 2 and "extras-bad.gltf: light 'lamp_a'" in p.stderr and
          "extras.lightmap_group is not a string" in p.stderr and not os.path.exists(out),
          "extras.lightmap_group 3: exit %d, %s" % (p.returncode, p.stderr.strip()[-200:]))


def one_per_light(lmbake, work, level, doc, short):
    """output.light_groups' one_per_light: a group per light, named after it; beyond 8 groups the
    lights that rank lowest share `rest`."""
    each = BASE + "output:\n  light_groups:\n    - {one_per_light: true}\n"
    named = BASE + "output:\n  light_groups:\n" + "".join(
        "    - {name: %s, match: %s}\n" % (n, n) for n in ("sun", "lamp_a", "lamp_b"))
    if not short:  # (Release only: the sanitizers' pass runs the same code below)
        out_each, p = bake(lmbake, work, level, "one-per-light", each)
        # random_lights baked those three groups named in the config first (with --layout-cache:
        # the bytes of a bake without it, as kept_between_bakes checks)
        out_named = os.path.join(work, "random-kept")
        if not os.path.exists(os.path.join(out_named, "sun-lamps.gltf")):
            out_named, _ = bake(lmbake, work, level, "one-per-light-named", named)
        listed = sorted(os.listdir(out_named)) if os.path.exists(os.path.join(out_named, "sun-lamps.gltf")) else []
        differ = [f for f in listed if p.returncode or not filecmp.cmp(os.path.join(out_named, f),
                                                                      os.path.join(out_each, f), shallow=False)]
        check(p.returncode == 0 and listed and not differ and
              [g["name"] for g in group_intensities_list(os.path.join(out_each, "sun-lamps.gltf"))] ==
              ["sun", "lamp_a", "lamp_b"],
              "one_per_light: groups sun, lamp_a, lamp_b, every one of %d files the bytes of the three named in the "
              "config%s" % (len(listed), " (differ: %s)" % differ if differ else ""))
    # 11 lights: the sun, the two lamps and torch_0..7 at 5, 10, ..., 40 cd (dimmer than the lamps)
    d = json.loads(json.dumps(doc))
    lights = d["extensions"]["KHR_lights_punctual"]["lights"]
    for k in range(8):
        lights.append({"name": "torch_%d" % k, "type": "point", "intensity": 5.0 * (k + 1), "color": [1, 1, 1]})
        d["nodes"].append({"name": "torch_%d" % k, "translation": [-2.0 + 0.5 * k, 1.0, 0.5],
                           "extensions": {"KHR_lights_punctual": {"light": len(lights) - 1}}})
        d["scenes"][0]["nodes"].append(len(d["nodes"]) - 1)
    path = os.path.join(os.path.dirname(level), "torches.gltf")
    with open(path, "w") as f:
        json.dump(d, f)
    quick = BASE + "bounces: 0\nprobes:\n  auto: false\n"
    out, p = bake(lmbake, work, path, "one-per-light-11", each.replace(BASE, quick), "--log")
    names = [g["name"] for g in group_intensities_list(os.path.join(out, "torches.gltf"))] if p.returncode == 0 else []
    want = ["sun", "lamp_a", "lamp_b", "torch_4", "torch_5", "torch_6", "torch_7", "rest"]
    said = [l for l in (p.stdout + p.stderr).splitlines() if "share 'rest'" in l]
    check(p.returncode == 0 and names == want and len(said) == 1 and
          "4 light(s) share 'rest' ('torch_0', 'torch_1', 'torch_2', 'torch_3')" in said[0],
          "one_per_light, 11 lights: groups %s (want %s); %s" % (names, want, said or (p.stdout + p.stderr)[-300:]))
    # the sky and the emissive surfaces: groups of their own when the entry takes every light; the
    # sky ranks after the sun, the surfaces by their power pi x area x luminance: the grey
    # material (106 m^2: the ground's 100, the cube's 6) at emissive strength S has 106 pi S,
    # which passes torch_5's 6 x 5 cd x 4 pi = 120 pi at S = 1.132: at 1.16 (2.5% above) the
    # surfaces take torch_5's group, at 1.10 (2.8% below) they share 'rest' with torch_0..4
    sky = "sky:\n  intensity: 500\n"
    cases = [(1.16, ["sun", "lamp_a", "lamp_b", "torch_6", "torch_7", "sky", "emissive", "rest"],
              "6 light(s) share 'rest' ('torch_0', 'torch_1', 'torch_2', 'torch_3', 'torch_4', 'torch_5')"),
             (1.10, ["sun", "lamp_a", "lamp_b", "torch_5", "torch_6", "torch_7", "sky", "rest"],
              "5 light(s) and the emissive surfaces share 'rest' ('torch_0', 'torch_1', 'torch_2', 'torch_3', "
              "'torch_4')")]
    for strength, want, line in cases:
        g = json.loads(json.dumps(d))
        g["materials"][0]["emissiveFactor"] = [1.0, 1.0, 1.0]
        g["materials"][0].setdefault("extensions", {})["KHR_materials_emissive_strength"] = \
            {"emissiveStrength": strength}
        g["extensionsUsed"] = sorted(set(g.get("extensionsUsed", []) + ["KHR_materials_emissive_strength"]))
        name = "torches-glowing-%g" % strength
        with open(os.path.join(os.path.dirname(level), name + ".gltf"), "w") as f:
            json.dump(g, f)
        out, p = bake(lmbake, work, os.path.join(os.path.dirname(level), name + ".gltf"), "one-per-light-" + name,
                      each.replace(BASE, quick + sky), "--log")
        names = [x["name"] for x in group_intensities_list(os.path.join(out, name + ".gltf"))] if not p.returncode else []
        said = [l for l in (p.stdout + p.stderr).splitlines() if "share 'rest'" in l]
        check(p.returncode == 0 and names == want and len(said) == 1 and line in said[0],
              "one_per_light, 11 lights, a sky, emissive surfaces at strength %g: groups %s (want %s); %s" %
              (strength, names, want, said or (p.stdout + p.stderr)[-300:]))
    doc["materials"][0]["emissiveFactor"] = [0.01, 0.01, 0.01]
    glowing = level.replace(".gltf", "-glowing.gltf")
    with open(glowing, "w") as f:
        json.dump(doc, f)
    doc["materials"][0].pop("emissiveFactor")
    if short:  # (the byte comparison: Release only)
        return errors_of_one_per_light(lmbake, work, level)
    out_each, p = bake(lmbake, work, glowing, "one-per-light-sky", each.replace(BASE, quick + sky))
    named_too = named.replace(BASE, quick + sky) + "    - {name: sky, sky: true}\n    - {name: emissive, emissive: true}\n"
    out_named, pn = bake(lmbake, work, glowing, "one-per-light-sky-named", named_too)
    listed = sorted(os.listdir(out_named)) if pn.returncode == 0 else []
    differ = [f for f in listed if p.returncode or not filecmp.cmp(os.path.join(out_named, f),
                                                                  os.path.join(out_each, f), shallow=False)]
    groups = group_intensities_list(os.path.join(out_each, "sun-lamps-glowing.gltf")) if not p.returncode else []
    check(p.returncode == 0 and listed and not differ and [g["name"] for g in groups] ==
          ["sun", "lamp_a", "lamp_b", "sky", "emissive"] and groups[3]["intensity"] == [500, 500, 500] and
          np.allclose(groups[4]["intensity"], [0.01] * 3, rtol=1e-6, atol=0),
          "one_per_light with a sky and emissive surfaces: groups %s, the sky's and the surfaces' weights %s, every "
          "one of %d files the bytes of the same groups named in the config%s" %
          ([g["name"] for g in groups], [g["intensity"] for g in groups[3:]], len(listed),
           " (differ: %s)" % differ if differ else ""))
    errors_of_one_per_light(lmbake, work, level)


def errors_of_one_per_light(lmbake, work, level):
    cases = [("one-per-light-named-too", BASE + "output:\n  light_groups:\n    - {name: x, one_per_light: true}\n",
              "one-per-light-named-too.yaml:4: key 'output.light_groups': one_per_light: true names its groups after "
              "its lights"),
             ("one-per-light-none", BASE + "output:\n  light_groups:\n    - {match: \"torch*\", one_per_light: true}\n",
              "one-per-light-none.yaml:4: output.light_groups (one_per_light) holds no light: no light's name or node "
              "name matches 'torch*'")]
    for name, config, want in cases:
        out, p = bake(lmbake, work, level, name, config)
        check(p.returncode == 2 and want in p.stderr and not os.path.exists(out),
              "%s: exit %d, nothing written, %r" % (name, p.returncode, p.stderr.strip()[-220:]))


def errors(lmbake, work, level):
    cases = [
        ("unused", BASE + "output:\n  light_groups:\n    - {name: sun, match: sun}\n    - {name: torches, match: \"torch*\"}\n",
         "unused.yaml:5: output.light_groups 'torches' holds no light: no light's name or node name matches 'torch*'"),
        ("bad-name", BASE + "output:\n  light_groups:\n    - {name: \"a b\", match: sun}\n",
         "bad-name.yaml:4: key 'output.light_groups': name 'a b': letters, digits, '_' and '-' only"),
        ("too-many", BASE + "output:\n  light_groups:\n" + "".join("    - {name: g%d, match: sun}\n" % i for i in range(9)),
         "too-many.yaml:12: key 'output.light_groups': expected at most 8 entries, got 9"),
        ("twice", BASE + "output:\n  light_groups:\n    - {name: a, match: sun}\n    - {name: a, match: lamp_a}\n",
         "twice.yaml:5: key 'output.light_groups': name 'a' is given twice (lines 4 and 5)"),
    ]
    for name, config, want in cases:
        out, p = bake(lmbake, work, level, name, config)
        check(p.returncode == 2 and want in p.stderr and not os.path.exists(out),
              "%s: exit %d, nothing written, %r" % (name, p.returncode, p.stderr.strip()[-220:]))


def main():
    lmbake, work = sys.argv[1:3]
    short = len(sys.argv) > 3 and sys.argv[3] == "short"
    os.makedirs(work, exist_ok=True)
    scenes, level, doc = make_level(work)
    engine(lmbake, work, level, short)
    kept_between_bakes(lmbake, work, level, doc, short)
    if not short:  # Release only: the sanitizers' pass reads unit groups back in the sun's edit
        random_lights(lmbake, work, level, doc, short)
    extras_group(lmbake, work, level, doc)
    one_per_light(lmbake, work, level, doc, short)
    errors(lmbake, work, level)
    print("%d failed" % len(fails))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
