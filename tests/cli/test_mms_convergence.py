"""Manufactured solutions for Poisson and linear elasticity in 2D and 3D on 4 refinements:
L2 rate >= 1.9 and H1 rate >= 0.95, and the errors agree to 1e-9 relative on 1, 2 and 3 ranks
(direct solver, so the partition does not change the discrete solution beyond round-off)."""

import math

from cli_common import Runner, parse_arguments, read_json

DIRECT = ["-ksp_type", "preonly", "-pc_type", "lu", "-pc_factor_mat_solver_type", "mumps"]
CASES = [("poisson", "mms2d", 4), ("poisson", "mms3d", 4), ("elasticity", "mms2d", 4), ("elasticity", "mms3d", 4)]


def solver_options(problem):
    return [f"-{problem}_{option[1:]}" if option.startswith("-") else option for option in DIRECT]


def main():
    arguments = parse_arguments()
    r = Runner(arguments)
    for problem, name, n_levels in CASES:
        case = r.source / "cases" / problem / f"{name}.yaml"
        errors = {}
        for level in range(n_levels):
            out = r.work / f"{problem}-{name}-L{level}-np1"
            result = r.run("run", case, "--output", out, "--set", f"mesh.level={level}", "--set", "output.vtk=false",
                           "--", *solver_options(problem))
            if result.returncode != 0:
                r.expect(False, f"{problem} {name} level {level} runs", result.stdout + result.stderr)
                break
            b = read_json(out / "summary.json")["benchmark"]
            errors[level] = (b["h"], b["l2_error"], b["h1_error"])
            print(f"{problem} {name} level {level}: h = {b['h']:.4e}  L2 = {b['l2_error']:.6e}  H1 = {b['h1_error']:.6e}")
        levels = sorted(errors)
        for a, b in zip(levels, levels[1:]):
            (h0, l20, h10), (h1, l21, h11) = errors[a], errors[b]
            l2_rate = math.log(l20 / l21) / math.log(h0 / h1)
            h1_rate = math.log(h10 / h11) / math.log(h0 / h1)
            r.expect(l2_rate >= 1.9, f"{problem} {name} L2 rate level {a}->{b} = {l2_rate:.3f} >= 1.9")
            r.expect(h1_rate >= 0.95, f"{problem} {name} H1 rate level {a}->{b} = {h1_rate:.3f} >= 0.95")
        # Rank independence on the second finest level.
        level = max(levels[-2] if len(levels) > 1 else 0, 0)
        for ranks in (2, 3):
            out = r.work / f"{problem}-{name}-L{level}-np{ranks}"
            result = r.run("run", case, "--output", out, "--set", f"mesh.level={level}", "--set", "output.vtk=false",
                           "--", *solver_options(problem), ranks=ranks)
            if result.returncode != 0:
                r.expect(False, f"{problem} {name} on {ranks} ranks runs", result.stdout + result.stderr)
                continue
            b = read_json(out / "summary.json")["benchmark"]
            _, l2, h1 = errors[level]
            difference = max(abs(b["l2_error"] - l2) / l2, abs(b["h1_error"] - h1) / h1)
            r.expect(difference < 1e-9, f"{problem} {name} level {level}: {ranks} ranks agree with 1 rank "
                                        f"(relative difference {difference:.1e} < 1e-9)")
    r.finish()


if __name__ == "__main__":
    main()
