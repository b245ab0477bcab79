"""Time per Newton iteration of our seepage solver against FEniCSx on the same problem.

usage: /usr/bin/python3 seepage_fe/benchmark/compare_fenicsx.py [--build build] [--cells 315 999]
           [--rounds 3] [--steps 3] [--threads 2] [--loose-tolerance 1e-4] [--csv FILE]

The problem is seepage-benchmark's: the unit square in n x n Q1 quadrilaterals, the gas law
d/dt(A P^(1/4)) = div(lambda grad P) with A = 2, lambda = 0.1, P = 9 at t = 0 and P = 1 on
the left side, the storage lumped at the nodes, backward Euler with steps of 1e-3, Newton to
an update of 1e-10 of P. FEniCSx (0.5, Debian's python3-dolfinx) writes it in UFL with the
storage integrated at the cell corners (Gauss-Lobatto, degree 1: the lumped storage) and
solves it with its NewtonSolver and MUMPS LU, as its users would; it runs as one process
with `--threads` OpenBLAS threads and as `--threads` MPI processes, and the faster of the
two is the reference. Ours runs seepage-benchmark with `--threads` threads under each of
its linear solvers (direct, cg and lagged at seepage.cg_tolerance's default, lagged with
Eisenstat and Walker's forcing term down to that default (seepage.cg_forcing = "adaptive"),
and lagged at `--loose-tolerance`), each a run of `--steps` steps from the state after a first step, the
first of them factorising afresh; each row says how far its solution lies from the direct
one's (max |u - u_direct| / max |u_direct|). Each timed step is a whole Newton solve
(assemblies, factorisations, solves), divided by its iterations: FEniCSx's best step, our
run's mean; the mesh, the forms' compilation and a first step are not timed. Rounds
alternate ours and theirs and each keeps its best round, since the machine may be shared.

Without dolfinx it says so and exits 0: this is a benchmark, not a test. The processor is
printed first and written as the CSV's last column, host: the ratios depend on it (README.md,
"The same builds on another processor").
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
TOP = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(TOP, "scripts"))
from builds import host  # noqa: E402 (scripts/builds.py)

TIME_STEP = 1e-3


def fenicsx_worker(cells, steps):
    """Runs the problem in FEniCSx; rank 0 prints {"newton_iteration_s", "newton_iterations"}."""
    import time

    import numpy as np
    import ufl
    from dolfinx import fem, mesh
    from dolfinx.fem.petsc import NonlinearProblem
    from dolfinx.nls.petsc import NewtonSolver
    from mpi4py import MPI
    from petsc4py import PETSc

    comm = MPI.COMM_WORLD
    domain = mesh.create_unit_square(comm, cells, cells, mesh.CellType.quadrilateral)
    V = fem.FunctionSpace(domain, ("Lagrange", 1))
    u, u_old, v = fem.Function(V), fem.Function(V), ufl.TestFunction(V)
    u.x.array[:] = 9.0
    u_old.x.array[:] = 9.0
    left = fem.locate_dofs_geometrical(V, lambda x: np.isclose(x[0], 0.0))
    bc = fem.dirichletbc(PETSc.ScalarType(1.0), left, V)
    A, lam = 2.0, 0.1
    dt = fem.Constant(domain, PETSc.ScalarType(TIME_STEP))
    corners = ufl.dx(metadata={"quadrature_rule": "GLL", "quadrature_degree": 1})
    F = (A * (u ** 0.25 - u_old ** 0.25) * v * corners
         + dt * lam * ufl.inner(ufl.grad(u), ufl.grad(v)) * ufl.dx)
    problem = NonlinearProblem(F, u, bcs=[bc])
    solver = NewtonSolver(comm, problem)
    solver.convergence_criterion = "incremental"
    solver.rtol = 1e-10
    solver.atol = 1e-12
    solver.max_it = 30
    ksp = solver.krylov_solver
    opts = PETSc.Options()
    prefix = ksp.getOptionsPrefix()
    opts[f"{prefix}ksp_type"] = "preonly"
    opts[f"{prefix}pc_type"] = "lu"
    opts[f"{prefix}pc_factor_mat_solver_type"] = "mumps"
    ksp.setFromOptions()

    best, iterations = float("inf"), []
    for step in range(steps + 1):
        comm.Barrier()
        start = time.perf_counter()
        n, converged = solver.solve(u)
        comm.Barrier()
        elapsed = time.perf_counter() - start
        if not converged:
            raise RuntimeError(f"FEniCSx's Newton did not converge in step {step}")
        u_old.x.array[:] = u.x.array
        if step > 0:  # the first step sets up PETSc's matrices and MUMPS's analysis
            best = min(best, elapsed / n)
            iterations.append(n)
    if comm.rank == 0:
        print(json.dumps({"newton_iteration_s": best, "newton_iterations": sum(iterations) / len(iterations),
                          "unknowns": V.dofmap.index_map.size_global}))


def run_json(command, env):
    out = subprocess.run(command, env=env, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"{' '.join(command)} failed ({out.returncode}):\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def fenicsx(cells, steps, processes, threads):
    env = dict(os.environ, OPENBLAS_NUM_THREADS=str(threads), OMP_NUM_THREADS=str(threads),
               OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    command = [sys.executable, os.path.abspath(__file__), "--worker", str(cells), "--steps", str(steps)]
    if processes > 1:
        command = ["mpirun", "-n", str(processes), "--bind-to", "none"] + command
    return run_json(command, env)


def ours(build, cells, steps, threads, loose_tolerance):
    """{contender: seepage-benchmark's Newton row} for each of our linear solvers."""
    runs = ((("direct", "cg", "lagged", "lagged-adaptive"), None, ""), (("direct", "lagged"), loose_tolerance, f", cg_tolerance {loose_tolerance:g}"))
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "newton.csv")
        for solvers, tolerance, suffix in runs:
            command = [os.path.join(build, "seepage_fe", "seepage-benchmark"), str(cells), "--no-orderings",
                       "--rounds", "1", "--steps", str(steps), "--time-step", str(TIME_STEP), "--csv", path,
                       "--linear-solvers", *solvers]
            if tolerance is not None:
                command += ["--cg-tolerance", str(tolerance)]
            env = dict(os.environ, OMP_NUM_THREADS=str(threads))
            out = subprocess.run(command, env=env, capture_output=True, text=True)
            if out.returncode != 0:
                sys.exit(f"{' '.join(command)} failed ({out.returncode}):\n{out.stderr}")
            with open(path, newline="") as f:
                for r in csv.DictReader(f):
                    if r["linear_solver"] in solvers[1:] or not suffix:
                        rows[f"ours, {r['linear_solver']}{suffix}"] = r
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--worker", type=int, metavar="CELLS", help=argparse.SUPPRESS)
    parser.add_argument("--build", default=os.path.join(TOP, "build"))
    parser.add_argument("--cells", type=int, nargs="+", default=[315, 999],
                        help="cells per side (unknowns (n + 1)^2; default about 1e5 and 1e6)")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--steps", type=int, default=3, help="timed steps per run, after one untimed")
    parser.add_argument("--loose-tolerance", type=float, default=1e-4,
                        help="seepage.cg_tolerance of the second lagged row (the Newton iterations still stop at "
                             "the same nonlinear tolerance; the rows say how far the solution moves)")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--csv", help="write the table to this CSV (seepage_fe/benchmark/fenicsx.csv is one)")
    args = parser.parse_args(argv)
    for name, value in (("--rounds", args.rounds), ("--steps", args.steps), ("--threads", args.threads)):
        if value < 1:
            parser.error(f"{name} must be at least 1, got {value}")
    if not 0 < args.loose_tolerance < 1:
        parser.error(f"--loose-tolerance must lie in (0, 1), got {args.loose_tolerance}")
    if any(n < 2 for n in args.cells):
        parser.error("--cells: each must be at least 2")
    if args.worker is not None:
        fenicsx_worker(args.worker, args.steps)
        return 0
    try:
        import dolfinx
    except ImportError:
        print("compare_fenicsx: dolfinx is not installed (apt-get install python3-dolfinx); nothing measured")
        return 0
    if not os.access(os.path.join(args.build, "seepage_fe", "seepage-benchmark"), os.X_OK):
        sys.exit(f"compare_fenicsx: no {args.build}/seepage_fe/seepage-benchmark: build first (scripts/build.sh)")

    mine_names = ["ours, direct", "ours, cg", "ours, lagged", "ours, lagged-adaptive", f"ours, lagged, cg_tolerance {args.loose_tolerance:g}"]
    fenicsx_names = ["FEniCSx, 1 process", f"FEniCSx, {args.threads} processes"]
    contenders = mine_names + fenicsx_names
    rows = []
    machine = host()
    print(f"FEniCSx {dolfinx.__version__}; {args.rounds} rounds of {args.steps} steps, best kept; "
          f"{args.threads} threads; on {machine}")
    for cells in args.cells:
        best = {c: None for c in contenders}

        def keep(name, time, iterations, difference=""):
            if best[name] is None or time < best[name][0]:
                best[name] = (time, iterations, difference)

        for r in range(args.rounds):
            mine = ours(args.build, cells, args.steps, args.threads, args.loose_tolerance)
            for name in mine_names:
                row = mine[name]
                keep(name, float(row["newton_iteration_s"]), float(row["newton_iterations"]) / args.steps,
                     row["difference"])
            for processes, name in ((1, fenicsx_names[0]), (args.threads, fenicsx_names[1])):
                theirs = fenicsx(cells, args.steps, processes, args.threads if processes == 1 else 1)
                keep(name, theirs["newton_iteration_s"], theirs["newton_iterations"])
            print(f"  {(cells + 1) ** 2} unknowns, round {r + 1}: "
                  + ", ".join(f"{c} {best[c][0]:.4f} s" for c in contenders), flush=True)
        reference = min(best[c][0] for c in fenicsx_names)
        for c in contenders:
            rows.append({"unknowns": (cells + 1) ** 2, "contender": c, "threads": args.threads,
                         "newton_iteration_s": f"{best[c][0]:.6g}", "newton_iterations": f"{best[c][1]:.3g}",
                         "fenicsx_over_this": f"{reference / best[c][0]:.3f}", "difference": best[c][2],
                         "host": machine})
    print(f"\n{'unknowns':>9} {'contender':<36} {'per Newton it. [s]':>18} {'its/step':>8} {'FEniCSx/this':>12} "
          f"{'differs':>9}")
    for r in rows:
        print(f"{r['unknowns']:>9} {r['contender']:<36} {float(r['newton_iteration_s']):>18.4f} "
              f"{r['newton_iterations']:>8} {r['fenicsx_over_this']:>12} {r['difference']:>9}")
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
