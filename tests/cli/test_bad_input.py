"""Bad input gives one clear message naming the file, key or element, and a non-zero exit
(2 for input errors), never a crash."""

from pathlib import Path

from cli_common import Runner, parse_arguments


def write(path, text):
    path.write_text(text)
    return path


def main():
    arguments = parse_arguments()
    r = Runner(arguments)
    work = r.work
    cases = r.source / "cases"
    meshes = r.source / "tests" / "data" / "meshes"

    def expect_input_error(name, args, must_contain, ranks=1):
        result = r.run(*args, ranks=ranks)
        errors = [line for line in result.stderr.splitlines() if line.startswith("coapt: error:")]
        ok = (result.returncode == 2 and len(errors) == 1 and all(text in errors[0] for text in must_contain))
        r.expect(ok, f"{name} (ranks {ranks}) -> exit 2 with one message naming {must_contain}",
                 f"exit {result.returncode}\nstdout:\n{result.stdout}\nstderr:\n{result.stderr}")

    square = "problem: poisson\nmesh:\n  type: rectangle\n  cells: [4, 4]\n"
    expect_input_error("missing case file", ["check", work / "nothing.yaml"], ["nothing.yaml", "no such file"])
    malformed = write(work / "malformed.yaml", "problem: poisson\nmesh: [1, 2\n")
    expect_input_error("malformed YAML", ["check", malformed], ["malformed.yaml:", "malformed YAML"])
    unknown = write(work / "unknown.yaml", square + "  levle: 2\n")
    expect_input_error("unknown key", ["check", unknown], ["unknown.yaml:5", "mesh.levle", "unknown key"])
    for ranks in (2, 3):
        expect_input_error("unknown key", ["check", unknown], ["unknown.yaml:5", "mesh.levle"], ranks=ranks)
    wrong_type = write(work / "wrong_type.yaml", square + "  level: two\n")
    expect_input_error("wrong type", ["check", wrong_type], ["wrong_type.yaml:5", "mesh.level", "expected an integer"])
    negative = write(work / "negative.yaml", "problem: elasticity\nmesh:\n  type: rectangle\nmaterial:\n  young_modulus: -3\n")
    expect_input_error("non-physical value", ["check", negative], ["negative.yaml:5", "material.young_modulus", "out of range"])
    expect_input_error("--set with a wrong value", ["check", cases / "poisson" / "mms2d.yaml", "--set", "mesh.cells=[4, x]"],
                       ["--set mesh.cells=[4, x]", "mesh.cells"])
    expect_input_error("--set on an unknown key", ["check", cases / "poisson" / "mms2d.yaml", "--set", "mesh.size_x=1"],
                       ["mesh.size_x", "unknown key"])
    expect_input_error("a 3D-only benchmark key in 2D",
                       ["run", cases / "dfg" / "2d1.yaml", "--output", work / "o2", "--set", "benchmark.height=0.41"],
                       ["benchmark.height", "3D"])
    expect_input_error("a per-solid checkpoint interval in a coupled case",
                       ["run", cases / "turek_hron" / "fsi1.yaml", "--output", work / "o3",
                        "--set", "solids[0].output.checkpoint_interval=5"],
                       ["solids[0].output.checkpoint_interval", "output.checkpoint_interval"])
    expect_input_error("an iteration density in a steady coupled case",
                       ["check", cases / "turek_hron" / "fsi1.yaml",
                        "--set", "coupling.iteration.iteration_density=1000"],
                       ["coupling.iteration.iteration_density", "transient"])
    expect_input_error("the fluid's pressure in a solid of the mixed formulation",
                       ["run", cases / "turek_hron" / "fsi1.yaml", "--output", work / "o4",
                        "--set", "solids[0].formulation=mixed", "--set",
                        "solids[0].bodies[0].material.model=nearly_incompressible_neo_hookean"],
                       ["fsi1.yaml:28", "solid 'bar'", "coupling.pressure_in_solid", "mixed"])
    unknown_problem = write(work / "unknown_problem.yaml", "problem: poison\n")
    expect_input_error("unknown problem", ["check", unknown_problem], ["unknown_problem.yaml:1", "problem", "poison"])

    missing_mesh = write(work / "missing_mesh.yaml", "problem: poisson\nmesh:\n  type: gmsh\n  file: nowhere.msh\n")
    expect_input_error("missing mesh file", ["check", missing_mesh], ["nowhere.msh"])
    for ranks in (1, 3):
        expect_input_error("missing mesh file", ["run", missing_mesh, "--output", work / "o1"], ["nowhere.msh"], ranks=ranks)

    good = meshes / "square_v2.msh"
    text = good.read_text()
    truncated = write(work / "truncated.msh", text[: len(text) // 2])
    expect_input_error("truncated mesh", ["mesh", truncated], ["truncated.msh"])
    garbage = write(work / "garbage.msh", text.replace("$Nodes", "$Nodes\nthis is not a node line", 1))
    expect_input_error("malformed mesh", ["mesh", garbage], ["garbage.msh"])
    case_truncated = write(work / "case_truncated.yaml", f"problem: poisson\nmesh:\n  type: gmsh\n  file: {truncated}\n")
    expect_input_error("truncated mesh in a case", ["check", case_truncated], ["truncated.msh"], ranks=2)

    inverted = meshes / "inverted_tet.msh"
    expect_input_error("inverted element", ["mesh", inverted], ["inverted_tet.msh", "inverted"])
    case_inverted = write(work / "case_inverted.yaml", f"problem: poisson\nmesh:\n  type: gmsh\n  file: {inverted}\n")
    expect_input_error("inverted element in a case", ["check", case_inverted], ["inverted_tet.msh", "inverted"], ranks=2)

    missing_group = write(work / "missing_group.yaml",
                          f"problem: poisson\nmesh:\n  type: gmsh\n  file: {good}\ndirichlet: [left, inlet]\n")
    expect_input_error("physical group missing from the mesh", ["check", missing_group],
                       ["missing_group.yaml:5", "dirichlet", "inlet", "square_v2.msh"])

    result = r.run("frobnicate")
    r.expect(result.returncode != 0 and result.returncode < 128, "unknown sub-command -> non-zero exit", result.stderr)
    r.finish()


if __name__ == "__main__":
    main()
