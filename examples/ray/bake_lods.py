"""Fan a LOD bake out over Ray: one Ray task per asset, through the pleat Python package.

    python examples/ray/bake_lods.py MESH_OR_DIR... --screen-sizes 50,25 --out OUT_DIR
        [--address auto] [--num-cpus N] [--max-rounds N] [--report report.json]

Each task reads its asset, bakes the LOD chain with pleat, writes ``<stem>_<n_p>.obj`` into
OUT_DIR atomically (temporary file + rename) and returns a report row (status, faces, error,
seconds, BLAKE2 digest of every output). A failing asset is a ``failed`` row, never the end of
the fan-out; the script exits 1 when any asset failed. With ``--verify-local`` it bakes every
asset again in this process and checks that the distributed outputs are byte-identical:
pleat's bakes are deterministic (independent of thread count and machine scheduling), which
is what lets a build system with remote execution cache them by input digest.

Without ``--address`` Ray starts a local cluster on this machine (what .ci/ray.sh runs); with
``--address auto`` (or ray://...) the same tasks run on an existing cluster, whose workers
need the pleat package installed (``pip install ./bindings/python``) and OUT_DIR on a shared
file system (or change ``bake_asset`` to return the bytes).
"""
import argparse
import hashlib
import json
import os
import sys
import time

import ray

MESH_EXTENSIONS = (".obj", ".ply", ".off", ".stl", ".glb", ".gltf")


def mesh_files(paths):
    """Files named, and mesh files under folders named, sorted within each folder."""
    out = []
    for p in paths:
        if os.path.isdir(p):
            for dirpath, _, files in sorted(os.walk(p)):
                out += [os.path.join(dirpath, f) for f in sorted(files)
                        if f.lower().endswith(MESH_EXTENSIONS) and not f.startswith(".")]
        else:
            out.append(p)
    return out


def bake(path, sizes, out_dir, max_rounds):
    """Bakes one asset's chain into out_dir; returns its report row (never raises for a bad
    asset). Plain function: the Ray task and the local check both call it."""
    import pleat
    start = time.perf_counter()
    row = {"input": path, "status": "baked", "error": None, "levels": []}
    try:
        with pleat.Mesh.read(path) as mesh:
            chain = mesh.lod_chain(sizes, max_rounds=max_rounds)
        stem = os.path.splitext(os.path.basename(path))[0]
        os.makedirs(out_dir, exist_ok=True)
        for n_p, lod in zip(sizes, chain):
            with lod:
                out = os.path.join(out_dir, f"{stem}_{n_p:g}.obj")
                tmp = os.path.join(out_dir, f".tmp-{os.getpid()}-{stem}_{n_p:g}.obj")
                lod.write(tmp)
                os.replace(tmp, out)
                with open(out, "rb") as f:
                    digest = hashlib.blake2b(f.read(), digest_size=16).hexdigest()
                row["levels"].append({"screen_size": n_p, "output": out,
                                      "faces": lod.triangle_count,
                                      "hausdorff_relative": lod.stats["hausdorff_relative"],
                                      "digest": digest})
    except Exception as e:  # noqa: BLE001 - a bad asset is a failed row
        row.update(status="failed", error=f"{type(e).__name__}: {e}", levels=[])
    row["seconds"] = round(time.perf_counter() - start, 3)
    return row


@ray.remote
def bake_asset(path, sizes, out_dir, max_rounds):
    """The Ray task: one asset."""
    row = bake(path, sizes, out_dir, max_rounds)
    row["node"] = ray.get_runtime_context().get_node_id()[:8]
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("inputs", nargs="+")
    ap.add_argument("--screen-sizes", default="50,25")
    ap.add_argument("--out", required=True)
    ap.add_argument("--max-rounds", type=int, default=50)
    ap.add_argument("--address", default=None)
    ap.add_argument("--num-cpus", type=int, default=None)
    ap.add_argument("--report", default=None)
    ap.add_argument("--verify-local", action="store_true")
    a = ap.parse_args()
    sizes = [float(s) for s in a.screen_sizes.split(",")]
    assets = mesh_files(a.inputs)
    out_dir = os.path.abspath(a.out)

    ray.init(address=a.address, num_cpus=a.num_cpus, include_dashboard=False,
             log_to_driver=False, runtime_env={"env_vars": {
                 k: os.environ[k] for k in ("PLEAT_LIBRARY", "PYTHONPATH") if k in os.environ}})
    start = time.perf_counter()
    rows = ray.get([bake_asset.remote(os.path.abspath(p), sizes, out_dir, a.max_rounds)
                    for p in assets])
    wall = time.perf_counter() - start
    ray.shutdown()

    for r in rows:
        if r["status"] == "failed":
            print(f"{os.path.basename(r['input'])}: FAILED: {r['error']}")
            continue
        faces = ", ".join(f"n_p={lv['screen_size']:g}: {lv['faces']}" for lv in r["levels"])
        print(f"{os.path.basename(r['input'])}: {faces} triangles, {r['seconds']:.2f} s "
              f"(node {r['node']})")
    failed = sum(r["status"] == "failed" for r in rows)
    print(f"ray: {len(rows)} tasks, {len(rows) - failed} baked, {failed} failed, "
          f"{wall:.1f} s wall")
    if a.verify_local:
        local_dir = out_dir + "-local"
        same = 0
        for r in rows:
            if r["status"] == "failed":
                continue
            local = bake(r["input"], sizes, local_dir, a.max_rounds)
            assert [lv["digest"] for lv in local["levels"]] == \
                [lv["digest"] for lv in r["levels"]], f"{r['input']}: outputs differ"
            same += len(local["levels"])
        print(f"determinism: {same} outputs of the Ray tasks are byte-identical to local bakes")
    if a.report:
        with open(a.report, "w") as f:
            json.dump({"assets": rows, "failed": failed}, f, indent=2)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
