"""What each command of the command line is for, as ``rigidfold COMMAND --help`` says it:
its one-line ``help`` and its ``description`` (what it writes, its exit codes)."""

from __future__ import annotations

from rigidfold.config import DEFAULTS

COMMANDS: dict[str, dict[str, str]] = {
    "generate": {
        "help": "Steps 2-7: fix crease lines one by one down to the target DOF",
        "description": (
            "Generate developable, rigid-foldable shapes of decreasing DOF. Writes "
            "DIR/solutions/step_XX_dof_YY.fold, DIR/log.jsonl and DIR/summary.json as it goes; the "
            "last line names the final design (the last solution). Exit code 0 when the target DOF "
            "was reached and every check that ran on the final design (development diagram, "
            "folding motion, large deformation; thick panels and structure with --thickness and "
            "--structure) passed, 1 when the run fell short (the files are "
            "written all the same; the last line says what fell short, and notes the checks that "
            "failed on earlier solutions), 2 on bad input, 130 when interrupted."
        ),
    },
    "report": {
        "help": "DIR/report.html of a generate run: the answer, 3D view, figures and tables",
        "description": (
            "Write DIR/report.html (one self-contained page that opens offline: the "
            "final design in 3D with its folding motion, the figures, the tables of summary.json) "
            "and DIR/figures/*.png for the generate run in DIR."
        ),
    },
    "analyze": {
        "help": "mechanism analysis of a FOLD shape: DOF, locked creases, fold angles",
        "description": (
            "Read a FOLD file (3D vertices_coords; polygon faces are triangulated with "
            "fixed 'J' edges) and report its DOF and locked crease lines."
        ),
    },
    "develop": {
        "help": "Step 8: development diagram of a FOLD shape (problem 13)",
        "description": (
            "Flatten a FOLD shape to its development diagram. Writes DIR/<name>.fold "
            "(the input plus a 'creasePattern' frame with 2D coordinates) and DIR/<name>.svg. Exit "
            "code 0 when the development converged, 1 when not, 2 on bad input."
        ),
    },
    "deform": {
        "help": "Step 9: large-deformation check of a FOLD shape (OpenSees) and its folding motion",
        "description": (
            "Drive the frame model of a FOLD shape to the plane with OpenSees (tubes "
            f"{DEFAULTS.deformation.tube_diameter * 1e3:g} mm x "
            f"{DEFAULTS.deformation.tube_wall * 1e3:g} mm, E = "
            f"{DEFAULTS.deformation.youngs_modulus / 1e9:g} GPa, "
            f"{DEFAULTS.deformation.steps} load steps) and trace "
            "its folding motion (a rigid-folding path from the plane, the support panel held "
            "still); a line says whether the two verdicts agree and, when not, why. Writes "
            "DIR/<name>.fold (the input plus the development diagram and the motion frames), "
            "DIR/<name>.svg (the development diagram) and DIR/<name>_deform.json (figures and the "
            "load-step history). Exit code 0 when the plane is reached, 1 when not, 2 on bad "
            "input."
        ),
    },
    "export": {
        "help": (
            "3D, CAD and cut-sheet files of a FOLD design: OBJ, STL, PLY, GLB, DXF, SVG, CSV, "
            "FOLD for Origami Simulator"
        ),
        "description": (
            "Export a FOLD design (a solution of rigidfold generate, or any FOLD shape): "
            "its folded form as OBJ, STL, PLY and GLB (metres, one group or node per panel), its "
            "development diagram as a cut sheet in DXF and SVG (millimetres at 1:1), its panel "
            "and crease schedule as CSV, and its folded form as a FOLD file that Origami "
            "Simulator opens (fold-os: DIR/<name>.os.fold, y up, creases M, V, F, boundary B), "
            "into DIR/<name>.*. The diagram is the file's 'creasePattern' frame, or computed "
            "(Step 8) when it has none. Exit code 0 when written, 1 when the computed diagram did "
            "not converge (written all the same), 2 on bad input."
        ),
    },
    "structure": {
        "help": "supports that hold a FOLD design and its panels and hinges under load (OpenSees)",
        "description": (
            "Check the deployed structure of a FOLD design: the supports (given, or "
            "the fewest boundary vertices that make its mechanism first-order rigid with "
            "--supports auto), then a shell model in OpenSees (panels as plates of the material "
            "and thickness, free creases as hinges, fixed creases continuous) under self-weight "
            "and the --load terms: reactions, displacements, hinge moments, panel stresses and "
            "natural frequencies. Writes DIR/structure.json and DIR/structure.png (the deflected "
            "shape, scaled). Exit code 0 when the supports hold the mechanism and the largest "
            "displacement is within the limit, 1 when they leave a mechanism (named), the "
            "analysis does not converge or the limit is exceeded, 2 on bad input."
        ),
    },
    "fabricate": {
        "help": (
            "thick panels of a FOLD design that deploy without collision: solids, hinge "
            "and vertex schedules, nested cut sheets"
        ),
        "description": (
            "Turn the panels of a FOLD design (a solution of rigidfold generate) into "
            "solids of the given thickness on one side of the design surface, the hinge axes on "
            "the crease lines (Tachi's tapered thick panels): every hinge is bevelled for its fold "
            "range from flat to the design plus a clearance angle, and panels that meet at a "
            "vertex "
            "without a common hinge are relieved there. Every pair of solids is checked over the "
            "whole folding motion (the file's motion frames, or its traced folding path). Writes "
            "DIR/<name>_solids.glb, .stl, .obj and .3dm (Rhino: layers PANELS, HINGES, CREASES, "
            "LABELS), DIR/<name>_hinges.csv, DIR/<name>_vertices.csv, cut sheets in mm nested onto "
            "stock sheets (DIR/<name>_sheet_NN.dxf and .svg) and DIR/<name>_fabricate.json; the "
            "files of an earlier fabricate of the same design in DIR are refused unless "
            "--overwrite, and replacing the input is refused always. Exit "
            "code 0 when the deployment is collision-free, 1 when not (the files are written; the "
            "last line names the panels, the fraction folded where they meet and a thickness that "
            "would pass), 2 on bad input."
        ),
    },
    "deploy": {
        "help": (
            "the drive that deploys a DOF-1 design under its own weight: which crease, pair "
            "or cable to drive, its torque along the motion, dead points and brake zones"
        ),
        "description": (
            "Take a DOF-1 FOLD design (a solution of rigidfold generate) along its folding "
            "motion from flat (its motion frames, or traced) under self-weight: the panels' "
            "mass from --thickness (or the thickness fabricate recorded beside the design) and "
            "--material, hinge springs and friction, hardware and point masses; the base panel "
            "clamped. For every free crease as the single drive: its torque along the whole "
            "motion by virtual work (tau = dU/drho), its dead points (the crease stops turning, "
            "the torque is unbounded) and sign changes (the motion runs away: a brake must hold "
            "it), ranked by peak torque; a pair of creases where the best single one has a dead "
            "point; cables between vertices (tension, which must stay positive); where the "
            "released structure comes to rest; whether a vertex passes below the ground. "
            "Checked by OpenSees at five states (the driven crease held: its reaction moment "
            "against the curve). Writes DIR/deploy.json, DIR/deploy.fold (the motion as the "
            "builder sees it, base clamped), DIR/deploy.csv (the motor schedule) and "
            "DIR/deploy.png. The last line names the drive, its peak and the brake zones. Exit "
            "code 0 when a crease, pair or cable drives the whole motion within --max-torque / "
            "--max-tension with every vertex above the ground, 1 otherwise (the files are "
            "written all the same), 2 on bad input (a design that is not DOF 1, an index the "
            "design lacks, a negative mass)."
        ),
    },
    "study": {
        "help": "many generate runs on Dask, results in SQLite (Tables 5-8), resumable",
        "description": (
            "Run generate for every (Bezier seed, pattern, criterion), or a preset, on "
            "Dask workers; store each finished run in DB. Re-running the same command skips "
            "finished runs, so a killed study resumes where it stopped."
        ),
    },
    "study-report": {
        "help": "Tables 5-8 of a study database beside the paper's, with box plots",
    },
    "optimize": {
        "help": "solve problem (6): a developable polyhedron near a target surface",
        "description": (
            "Solve problem (6) once and write DIR/solution.fold and DIR/summary.json. "
            "Exit code 0 when the solution is accepted (F <= F_tol, constraints met), 1 when not "
            "(the files are written all the same), 2 on bad input. A DIR that holds an earlier "
            "run's files is refused unless --overwrite."
        ),
    },
}
