"""`tailbeam modes`: natural frequencies and mode shapes of the plate (FE model).

Prints a table with the analytic or published references and the relative errors where they
exist (SSSS: closed forms of both theories; two opposite edges S: Levy's exact Kirchhoff
solution; square CCCC/FFFF/CFFF: Leissa, Kirchhoff), and writes frequencies.csv (first
reference only) into --out (atomically); modes.vtu (ParaView) with --vtu and modes.png with
--png (figures and VTU cost more than a cached solve: only what is asked for is written).
Bad input names the option (--fmax, --count, --divisions, ...), also when the band is too
costly to compute (tailbeam.plate.fe.cost, estimated before anything is assembled).

With a scene file (SCENE) the plate is the scene's: its flat plate (size, material,
boundary, theory, mesh divisions, plate.fmax as the band unless --fmax/--count), or its
structure from plate.mesh (``tailbeam.plate.solid``: impact face, supports, material), whose
modes.vtu is the volume mesh with each mode's displacement vector
(``tailbeam.plate.solid.export``). The options that describe the plate are then refused.
"""

from tailbeam.errors import InputError
from tailbeam.io.output import atomic_output_dir, check_output_dir, describe
from tailbeam.physics.bodies import Plate
from tailbeam.physics.materials import BUILTIN_MATERIALS, get_material
from tailbeam.plate.export import PNG_MODES

THEORIES = ("auto", "kirchhoff", "mindlin")
# the plate options a scene file replaces, and their defaults without one
PLATE_OPTIONS = {
    "bc": "SSSS",
    "theory": "auto",
    "divisions": None,
    "mesh": None,
    "accuracy": 1e-3,
    "material": "carbon_steel",
    "size": (0.6, 0.6, 0.01),
}

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
        "scene",
        nargs="?",
        default=None,
        metavar="SCENE",
        help="a scene file (TOML): its plate, or its structure from plate.mesh, instead of "
        "the plate options",
    )
    parser.add_argument(
        "--bc",
        default=None,
        metavar="CODE",
        help="boundary code: C, S or F for the edges left, bottom, right, top "
        "(x=-a/2, y=-b/2, x=+a/2, y=+b/2) (default: SSSS)",
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
        default=None,
        choices=THEORIES,
        help="plate theory; auto chooses from --accuracy and the plate (default: auto)",
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
        "--accuracy",
        type=float,
        default=None,
        help="target relative frequency error (default: 0.001)",
    )
    parser.add_argument(
        "--material",
        default=None,
        choices=tuple(BUILTIN_MATERIALS),
        help="built-in material (default: carbon_steel)",
    )
    parser.add_argument(
        "--size",
        type=float,
        nargs=3,
        default=None,
        metavar=("A", "B", "H"),
        help="plate size a, b and thickness h in m (default: 0.6 0.6 0.01)",
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
    check_output_dir(args.out)
    if args.count is not None and args.count < 1:
        raise InputError("count", f"must be >= 1, got {args.count}")
    if args.scene is not None:
        return _run_scene(args)
    for name, default in PLATE_OPTIONS.items():
        if getattr(args, name) is None:
            setattr(args, name, default)
    return _run_options(args)


def _run_options(args) -> int:
    from tailbeam.plate import compute_modes

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
    return _report(args, basis, f"{basis.boundary} plate {a} x {b} x {h} m, {material.name}")


def _report(args, basis, what: str) -> int:
    """Print the flat plate's table (with references) and write its files."""
    refs = reference_frequencies(basis)
    info = basis.info
    print(
        f"{what}: {basis.n_modes} modes, {info['theory']} ({info['element']}), "
        f"{info['n_dofs']} DOFs, cache {info['cache']}"
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


def _run_scene(args) -> int:
    """``tailbeam modes SCENE``: the scene's flat plate or structure (module docstring)."""
    from tailbeam.io.scene_file import load_scene
    from tailbeam.plate import compute_modes

    given = [name for name in PLATE_OPTIONS if getattr(args, name) is not None]
    if given:
        raise InputError(f"--{given[0]}", "not with a scene file: the scene sets the plate")
    scene = load_scene(args.scene)
    settings = scene.modal
    if settings is None:
        raise InputError("plate.model", "must be 'modal' for tailbeam modes (a rigid plate "
                         "has no modes)")  # fmt: skip
    fmax = args.fmax if args.fmax is not None or args.count is not None else settings.fmax_hz
    if settings.mesh is not None:
        return _structure(args, scene, fmax)
    basis = compute_modes(scene.plate, settings.boundary, theory=settings.theory, fmax_hz=fmax,
                          count=args.count, divisions=settings.mesh_divisions,
                          use_cache=not args.no_cache)  # fmt: skip
    p = scene.plate
    what = f"{basis.boundary} plate {p.size_x} x {p.size_y} x {p.thickness} m, {p.material.name}"
    return _report(args, basis, what)


def _structure(args, scene, fmax) -> int:
    """The modes of the scene's structure from plate.mesh: a table, frequencies.csv and (with
    --vtu) the volume mesh's modes.vtu."""
    from tailbeam.plate.solid import structure_modes
    from tailbeam.plate.solid.held import held_structure
    from tailbeam.plate.solid.modes import cached_listing

    settings = scene.modal
    if fmax is None and args.count is None:
        raise InputError("--fmax", "a structure needs a band: give --fmax or --count, or "
                         "plate.fmax in the scene")  # fmt: skip
    if args.png:
        raise InputError("--png", "draws a flat plate's modes; for a structure use --vtu")
    model = held_structure(settings.mesh, settings.impact_face, settings.supports,
                           scene.plate.material)  # fmt: skip
    basis = None if args.vtu or args.no_cache else cached_listing(model, fmax_hz=fmax,
                                                                  count=args.count)  # fmt: skip
    if basis is None:  # not cached, or the shapes are wanted: the whole basis
        basis = structure_modes(model, fmax_hz=fmax, count=args.count, use_cache=not args.no_cache)
    info = basis.info
    print(
        f"structure {settings.mesh} ({basis.boundary}), {scene.plate.material.name}: "
        f"{basis.n_modes} modes, {info['theory']} ({info['element']}), {info['n_dofs']} DOFs, "
        f"cache {info['cache']}"
    )
    print(f"{'mode':>5} {'f [Hz]':>12}")
    for i, f in enumerate(basis.frequencies_hz):
        print(f"{i + 1:5d} {f:12.3f}")
    _write_structure(args, basis, settings.mesh)
    return 0


def _write_structure(args, basis, mesh) -> None:
    """frequencies.csv and, with --vtu, modes.vtu of a structure into --out (atomically)."""
    from tailbeam.plate import export
    from tailbeam.plate.solid.export import write_modes_vtu

    names = ["frequencies.csv"]
    with atomic_output_dir(args.out, command="tailbeam modes") as tmp:
        path = export.write_frequencies_csv(tmp / "frequencies.csv", basis.frequencies_hz,
                                            basis.theory)  # fmt: skip
        face = basis.info["impact_face"]
        describe(path, units={"frequency_hz": "Hz"}, boundary=basis.boundary,
                 theory=basis.theory, mesh=str(mesh), impact_face=face)  # fmt: skip
        if args.vtu:
            write_modes_vtu(tmp / "modes.vtu", basis)
            names.append("modes.vtu")
    print(f"wrote {', '.join(names)} to {args.out}")
