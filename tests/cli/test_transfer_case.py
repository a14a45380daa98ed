"""The transfer cases (cases/transfer/): a linear field is reproduced to round-off at the
constrained nodes, a smooth field converges at second order, the conservation holds (the slave
side against the master side), the results do not depend on the number of ranks, and the VTK
output of both meshes reads back with the fields the summary describes."""

import json
import math
import subprocess

from cli_common import Runner, parse_arguments, read_json


def run_case(r, case, name, ranks, *settings):
    out = r.work / name
    arguments = ["run", case, "--output", out]
    for setting in settings:
        arguments += ["--set", setting]
    result = r.run(*arguments, ranks=ranks)
    r.expect(result.returncode == 0, f"{name} runs on {ranks} rank(s)", result.stdout + result.stderr)
    summary = read_json(out / "summary.json") if (out / "summary.json").exists() else {}
    return out, summary.get("benchmark", {})


def check_conservation(r, name, b):
    r.expect(b.get("conservation_error", 1) < 1e-12,
             f"{name}: sum B m = master-side integral (relative difference {b.get('conservation_error')})")
    r.expect(b.get("overlap_volume_error", 1) < 1e-12,
             f"{name}: sum B_ij = master-side overlap volume (relative difference {b.get('overlap_volume_error')})")


def read_field(case_yaml):
    """The `field` section of a resolved case.yaml (block style, as coapt writes it)."""
    field, key, inside = {}, None, False
    for line in case_yaml.read_text().splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        if not line.startswith(" "):
            inside = line.startswith("field:")
            continue
        if not inside:
            continue
        text = line.strip()
        if text.startswith("- "):
            field[key].append(float(text[2:]))
            continue
        key, _, value = text.partition(":")
        value = value.strip()
        field[key] = float(value) if value else []
    return field


def read_vtk(r, pvd):
    reader = subprocess.run(["/usr/bin/python3", str(r.source / "tools" / "vtk_read.py"), str(pvd)],
                            capture_output=True, text=True)
    r.expect(reader.returncode == 0, f"tools/vtk_read.py reads {pvd.name}", reader.stderr)
    if reader.returncode != 0:
        return None
    step = json.loads(reader.stdout)["steps"][0]
    return step, {a["name"]: a["values"] for a in step["point_data"]}


def main():
    arguments = parse_arguments()
    r = Runner(arguments)
    cases = r.source / "cases" / "transfer"

    for dim in (2, 3):
        case = cases / f"analytic{dim}d.yaml"
        # A linear field: T = D^-1 B reproduces it at every constrained node.
        _, linear = run_case(r, case, f"linear{dim}d", 2, "field.amplitude=0")
        r.expect(linear.get("constrained_nodes", 0) > 0, f"{dim}D: some nodes are constrained")
        r.expect(linear.get("max_error", 1) < 1e-12 * linear.get("field_max", 0),
                 f"{dim}D linear field reproduced at the constrained nodes (max error {linear.get('max_error')})")
        check_conservation(r, f"{dim}D linear", linear)

        # A smooth field under refinement of both meshes. Rates as found (docs/verification/
        # transfer.md): 3D (structured, nested) max error 1.93, L2 1.66 from level 1 to 2 (the
        # constrained region still grows); 2D (unstructured Gmsh master, not nested) max error
        # 1.55, L2 1.71 (levels 0-3: max 1.4-1.55, L2 1.57-1.80).
        minimum_rate = {2: {"max_error": 1.45, "l2_error": 1.6}, 3: {"max_error": 1.8, "l2_error": 1.5}}[dim]
        errors = {}
        for level in (1, 2):
            _, b = run_case(r, case, f"smooth{dim}d-L{level}", 1, f"mesh.level={level}", "output.vtk=false")
            errors[level] = b
            print(f"{dim}D level {level}: slave h {b.get('slave_h')}, master h {b.get('master_h')}, "
                  f"max error {b.get('max_error')}, L2 error {b.get('l2_error')}, "
                  f"constrained {b.get('constrained_nodes')}")
            check_conservation(r, f"{dim}D smooth, level {level}", b)
        if all("max_error" in errors[level] for level in (1, 2)):
            for key in ("max_error", "l2_error"):
                rate = math.log2(errors[1][key] / errors[2][key])
                r.expect(rate > minimum_rate[key], f"{dim}D {key} rate level 1 -> 2 = {rate:.2f} > {minimum_rate[key]}")

        # The same run on 2 ranks (meshes partitioned independently): the same figures.
        out, parallel = run_case(r, case, f"smooth{dim}d-L1-np2", 2, "mesh.level=1")
        serial = errors[1]
        for key in ("constrained_nodes", "intersecting_pairs"):
            r.expect(parallel.get(key) == serial.get(key) and key in serial,
                     f"{dim}D: {key} on 2 ranks = on 1 rank ({parallel.get(key)}, {serial.get(key)})")
        for key in ("max_error", "l2_error", "integral_slave_side", "overlap_volume_slave_side"):
            a, b = parallel.get(key, math.nan), serial.get(key, math.nan)
            r.expect(abs(a - b) <= 1e-12 * abs(b), f"{dim}D: {key} on 2 ranks = on 1 rank ({a!r}, {b!r})")
        if dim == 2:
            r.expect("standard_max_error" in parallel, "2D: the standard variant is reported",
                     json.dumps(parallel))

        # VTK: both meshes with their fields; the error field is the summary's.
        field = read_field(out / "case.yaml")

        def exact(point):
            x = point[:dim]
            phase = sum(w * c for w, c in zip(field["wave"], x))
            return (field["value"] + sum(g * c for g, c in zip(field["gradient"], x))
                    + field["amplitude"] * math.sin(2 * math.pi * phase))

        master = read_vtk(r, out / "master.pvd")
        if master:
            step, arrays = master
            values = arrays.get("field", [])
            points = [step["points"]["values"][3 * i:3 * i + 3] for i in range(step["n_points"])]
            worst = max((abs(v - exact(p)) for v, p in zip(values, points)), default=math.inf)
            r.expect(len(values) == step["n_points"] and worst < 1e-13,
                     f"{dim}D VTK: the master carries the analytic field (max difference {worst:.1e})")
        slave = read_vtk(r, out / "slave.pvd")
        if slave:
            step, arrays = slave
            names = {"transferred", "exact", "error", "constrained"}
            r.expect(names <= set(arrays), f"{dim}D VTK: slave fields {sorted(arrays)}")
            if names <= set(arrays):
                points = [step["points"]["values"][3 * i:3 * i + 3] for i in range(step["n_points"])]
                worst = max(abs(v - exact(p)) for v, p in zip(arrays["exact"], points))
                r.expect(worst < 1e-13, f"{dim}D VTK: the slave's exact field is f (max difference {worst:.1e})")
                marked = [i for i, c in enumerate(arrays["constrained"]) if c == 1.0]
                mismatch = max(abs(arrays["error"][i] - (arrays["transferred"][i] - arrays["exact"][i]))
                               for i in marked)
                largest = max(abs(arrays["error"][i]) for i in marked)
                free = max(abs(arrays["error"][i]) for i, c in enumerate(arrays["constrained"]) if c != 1.0)
                r.expect(mismatch < 1e-14 and abs(largest - parallel.get("max_error", -1)) <= 1e-15,
                         f"{dim}D VTK: error = transferred - exact at the constrained nodes, max {largest!r}")
                r.expect(free == 0, f"{dim}D VTK: no error reported at unconstrained nodes")
    # Bad input: one clear message naming the key.
    case = cases / "analytic3d.yaml"
    result = r.run("check", case, "--set", "field.gradient=[1, 2]")
    r.expect(result.returncode == 2 and "field.gradient: expected 3 values" in result.stderr,
             "a 2-component gradient for a 3D mesh is rejected, naming the key", result.stderr)
    result = r.run("check", case, "--set", "mesh.master.placement.axis=[0, 0, 0]")
    r.expect(result.returncode == 2 and "mesh.master.placement.axis" in result.stderr,
             "a zero rotation axis is rejected, naming the key", result.stderr)
    r.finish()


if __name__ == "__main__":
    main()
