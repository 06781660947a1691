"""`tailbeam modes`: natural frequencies and mode shapes of the plate (FE model).

Prints a table with the analytic or published references and the relative errors where they
exist (SSSS: closed forms of both theories; two opposite edges S: Levy's exact Kirchhoff
solution; square CCCC/FFFF/CFFF: Leissa, Kirchhoff), and writes frequencies.csv (first
reference only) into --out (atomically); modes.vtu (ParaView) with --vtu and modes.png with
--png (figures and VTU cost more than a cached solve: only what is asked for is written).
Bad input names the option (--fmax, --count, --divisions, ...), also when the band is too
costly to compute (tailbeam.plate.fe.cost, estimated before anything is assembled).
"""

from tailbeam.errors import InputError
from tailbeam.io.output import atomic_output_dir, check_output_dir, describe
from tailbeam.physics.bodies import Plate
from tailbeam.physics.materials import BUILTIN_MATERIALS, get_material
from tailbeam.plate.export import PNG_MODES

THEORIES = ("auto", "kirchhoff", "mindlin")

# library field names -> the options a user typed (tailbeam.cli renames InputError fields)
CLI_FIELDS = {
    "boundary": "--bc",
    "fmax": "--fmax",
    "count": "--count",
    "theory": "--theory",
    "divisions": "--divisions",
    "mesh": "--mesh",
    "accuracy": "--accuracy",
    "material": "--material",
    "plate": "--size",
    "fmax_hz": "--fmax",  # compute_modes' keyword (also its cost refusal)
}


def add_arguments(parser):
    parser.add_argument(
        "--bc",
        default="SSSS",
        metavar="CODE",
        help="boundary code: C, S or F for the edges left, bottom, right, top "
        "(x=-a/2, y=-b/2, x=+a/2, y=+b/2)",
    )
    band = parser.add_mutually_exclusive_group()
    band.add_argument(
        "--fmax",
        type=float,
        default=None,
        metavar="HZ",
        help="every mode up to this frequency in Hz; not with --count (default: 10000)",
    )
    band.add_argument(
        "--count",
        type=int,
        default=None,
        metavar="N",
        help="the first N modes instead of a band; not with --fmax (default: the --fmax band)",
    )
    parser.add_argument(
        "--theory",
        default="auto",
        choices=THEORIES,
        help="plate theory; auto chooses from --accuracy and the plate",
    )
    parser.add_argument(
        "--divisions",
        type=int,
        default=None,
        metavar="N",
        help="structured mesh divisions per side; not with --mesh (default: from --accuracy)",
    )
    parser.add_argument(
        "--mesh",
        default=None,
        metavar="FILE",
        help="triangular mesh file in any format meshio reads (Gmsh .msh, .vtu, .xdmf, ...) "
        "with its edges named left, bottom, right, top (default: a generated mesh)",
    )
    parser.add_argument(
        "--accuracy", type=float, default=1e-3, help="target relative frequency error"
    )
    parser.add_argument(
        "--material",
        default="carbon_steel",
        choices=tuple(BUILTIN_MATERIALS),
        help="built-in material",
    )
    parser.add_argument(
        "--size",
        type=float,
        nargs=3,
        default=(0.6, 0.6, 0.01),
        metavar=("A", "B", "H"),
        help="plate size a, b and thickness h in m",
    )
    parser.add_argument("--no-cache", action="store_true", help="neither read nor write cache")
    parser.add_argument("--vtu", action="store_true", help="also write modes.vtu (ParaView)")
    parser.add_argument(
        "--png", action="store_true", help=f"also write modes.png (the first {PNG_MODES} modes)"
    )
    parser.add_argument("--out", default="out/modes", metavar="DIR", help="output folder")


def reference_frequencies(basis):
    """[(label, frequencies Hz)] known for this plate, the first matching the basis's theory
    when one does: SSSS closed forms of both theories, Levy's exact Kirchhoff solution (two
    opposite edges S), Leissa's table (square CCCC/FFFF/CFFF, Kirchhoff)."""
    from tailbeam.plate.closed_forms import leissa_frequencies, levy_frequencies, ssss_modes

    plate, n = basis.plate, basis.n_modes
    refs = []
    if basis.boundary == "SSSS":
        for theory in (basis.theory, "mindlin" if basis.theory == "kirchhoff" else "kirchhoff"):
            refs.append(
                (f"closed form SSSS {theory}", ssss_modes(plate, theory, count=n).frequencies_hz)
            )
        return refs
    levy = levy_frequencies(plate, basis.boundary, 1.05 * basis.frequencies_hz[-1])
    if levy is not None:
        refs.append(("exact Levy solution (Kirchhoff)", levy[:n]))
    leissa = leissa_frequencies(plate, basis.boundary)
    if leissa is not None:
        refs.append(("Leissa table (Kirchhoff, square plate)", leissa[:n]))
    return refs


def run(args) -> int:
    from tailbeam.plate import compute_modes

    check_output_dir(args.out)
    if args.count is not None and args.count < 1:
        raise InputError("count", f"must be >= 1, got {args.count}")
    material = get_material(args.material, field="material")
    a, b, h = args.size
    plate = Plate(material=material, size_x=a, size_y=b, thickness=h)
    basis = compute_modes(
        plate,
        args.bc,
        theory=args.theory,
        fmax_hz=args.fmax,
        count=args.count,
        mesh=args.mesh,
        divisions=args.divisions,
        accuracy=args.accuracy,
        use_cache=not args.no_cache,
    )
    refs = reference_frequencies(basis)
    info = basis.info
    print(
        f"{basis.boundary} plate {a} x {b} x {h} m, {material.name}: {basis.n_modes} modes, "
        f"{info['theory']} ({info['element']}), {info['n_dofs']} DOFs, cache {info['cache']}"
    )
    print(f"  why: {info['reason']}")
    head = f"{'mode':>5} {'f [Hz]':>12}"
    for i in range(len(refs)):
        head += f" {f'ref{i + 1} [Hz]':>13} {'rel. error':>10}"
    print(head)
    for i, f in enumerate(basis.frequencies_hz):
        line = f"{i + 1:5d} {f:12.3f}"
        for _, ref in refs:
            if i < len(ref):
                line += f" {ref[i]:13.3f} {(f - ref[i]) / ref[i]:10.2e}"
            else:
                line += f" {'':>13} {'':>10}"
        print(line)
    for i, (label, _) in enumerate(refs):
        print(f"ref{i + 1}: {label}")
    _write(args, basis, refs)
    return 0


def _write(args, basis, refs) -> None:
    """frequencies.csv, and modes.vtu / modes.png when asked for, into --out (atomically)."""
    from tailbeam.plate import export

    ref, ref_name = refs[0][1] if refs else None, refs[0][0] if refs else ""
    names = ["frequencies.csv"]
    with atomic_output_dir(args.out, command="tailbeam modes") as tmp:
        path = export.write_frequencies_csv(
            tmp / "frequencies.csv", basis.frequencies_hz, basis.theory, ref, ref_name
        )
        describe(
            path,
            units={"frequency_hz": "Hz", "reference_hz": "Hz", "rel_error": "1"},
            boundary=basis.boundary,
            theory=basis.theory,
            plate_m=[basis.plate.size_x, basis.plate.size_y, basis.plate.thickness],
        )
        if args.vtu:
            export.write_vtu(tmp / "modes.vtu", basis)
            names.append("modes.vtu")
        if args.png:
            export.write_png(tmp / "modes.png", basis)
            shown = min(PNG_MODES, basis.n_modes)
            names.append(f"modes.png (the first {shown} of {basis.n_modes} modes)")
    print(f"wrote {', '.join(names)} to {args.out}")
