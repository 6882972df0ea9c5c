/* The contact regime's complementarity solver: nonsmooth Gauss-Seidel on contact impulses, one
 * normal and one friction row per contact point, with the exact 2D Coulomb cone.
 *
 * Problem. Bodies k have velocities v_k = (vx, vy, omega) and inverse mass and inertia; a row couples
 * two bodies (either may be static) at a point. For impulses lambda = (lambda_n, lambda_t) per row the
 * velocities after the solve are v = v_start + M^-1 J^T lambda, and each row's relative velocities
 * u_n, u_t (body a's point relative to body b's, along the normal out of b and its tangent) satisfy
 *     0 <= lambda_n  _|_  u_n - target_n >= 0                        (unilateral, Signorini)
 *     lambda_t in [lo_t, hi_t], with u_t >= 0 at lo_t, u_t <= 0 at hi_t, u_t = 0 inside,
 *     lo_t = -mu lambda_n, hi_t = mu lambda_n                          (Coulomb, 2D cone: two edges)
 * A row whose point slipped along +t when the step began (slip > 0) has hi_t = 0, along -t lo_t = 0:
 * friction then only opposes that slip, which keeps lambda_t (u_t,start + u_t) <= 0 (see
 * docs/contact_regime.md, "Why the regime adds no energy").
 *
 * Method. Rows are visited in order; each normal row is projected onto lambda_n >= 0 with its own
 * effective mass, then its friction row onto the box of the current lambda_n (Moreau's nonsmooth
 * Gauss-Seidel, NSGS). Two consecutive rows of one body pair (a face's two points) have their normal
 * rows solved together exactly, as a 2 x 2 complementarity problem, before their friction rows.
 * Velocities are updated after every point (its normal row and its friction row read the velocities
 * once and write them once, the friction row's tangent velocity updated through A's coupling), so a
 * sweep costs O(rows).
 * Stopping rule (lc_contact_stop): a sweep whose largest change of any row, in velocity units
 * (|d lambda| times the row's inverse effective mass, m/s), is at most `tolerance` ends the solve:
 * every row then met its condition to `tolerance` when it was visited. With `body_tolerance`, so does
 * a sweep that changed no body's velocity component by more than it (a pile's impulses are not unique,
 * and Gauss-Seidel can trade them between rows sweep after sweep at velocities that no longer move).
 * From `loose_after` sweeps on, a sweep whose largest change is at most `loose_tolerance` ends it too.
 * Otherwise the solve ends after `max_sweeps` sweeps, or when that largest change, below
 * `stall_below`, has not halved over `stall_sweeps` sweeps (the iteration crawls; 0: never), and
 * reports it as its residual. A warm start (the impulses passed in) is applied
 * to the velocities first; a quiescent, well warm-started problem ends after one sweep. */
#ifndef LC_CONTACT_SOLVER_H
#define LC_CONTACT_SOLVER_H

/* One contact point as the solver sees it. The caller fills everything above `lambda_n`. */
typedef struct lc_contact_row {
    int a, b;              /* body indices into the solver's body arrays, -1 = static (infinite mass) */
    double nx, ny;         /* unit normal, out of body b (u_n > 0: separating) */
    double rna, rnb;       /* cross(r_a, n), cross(r_b, n): lever arms of the normal about each centre */
    double rta, rtb;       /* the same for the tangent t = (-ny, nx) */
    double target_n;       /* m/s, the least u_n the row allows */
    double mu;             /* Coulomb coefficient, >= 0 */
    int slip;              /* +1 / -1: the point slipped along +t / -t at the start (friction opposes it
                              only); 0: the whole cone */
    double lambda_n;       /* N s, normal impulse: warm start in, answer out */
    double lambda_t;       /* N s, friction impulse: warm start in, answer out */
    /* filled by the solver */
    double mass_n, mass_t; /* effective masses 1 / (J M^-1 J^T) of the normal and tangent row */
    int block;             /* 1: this row's and the next's normal rows (two points of one body pair) are
                              solved together, exactly */
    double k12, det;       /* the block's coupling and the determinant of its 2 x 2 matrix */
    double k_tn;           /* A's entry between this row's tangent and normal */
    double k_t1n2, k_t2n1, k_t2t1; /* a block's cross entries (first row: 1, next: 2) */
    double prev_n, prev_t; /* impulses before the last sweep, and the conjugate direction */
    double dir_n, dir_t;
} lc_contact_row;

/* When a solve stops (the stopping rule above). */
typedef struct lc_contact_stop {
    int max_sweeps;
    double tolerance;      /* m/s */
    int stall_sweeps;      /* 0: no stall rule */
    double stall_below;    /* m/s, the largest change below which the stall rule applies (INFINITY: always) */
    double body_tolerance; /* m/s, 0: off */
    int loose_after;       /* sweeps after which loose_tolerance ends the solve too */
    double loose_tolerance;/* m/s, 0: no looser tolerance */
} lc_contact_stop;

/* The rule of max_sweeps, tolerance and stall_sweeps alone (no body or loose tolerance). */
lc_contact_stop lc_contact_stop_rule(int max_sweeps, double tolerance, int stall_sweeps);

typedef struct lc_contact_solve {
    int sweeps;            /* sweeps done */
    double residual;       /* m/s, the last sweep's largest change (see the stopping rule) */
} lc_contact_solve;

/* Solves the rows in place. v: nbodies x 3 velocities (changed in place: the answer's velocities);
 * inv_mass, inv_inertia: nbodies each; scratch: nbodies x 6 doubles. Rows with a non-finite warm start
 * start from 0. */
lc_contact_solve lc_contact_solver_run(lc_contact_row *rows, int nrows, int nbodies, double *v, const double *inv_mass,
                                       const double *inv_inertia, const lc_contact_stop *stop, double *scratch);

/* Adds the impulse dn along the row's normal and dt along its tangent to its two bodies' velocities v. */
void lc_contact_row_apply(const lc_contact_row *r, double dn, double dt, double *v, const double *inv_mass,
                          const double *inv_inertia);
/* u_n and u_t of a row at velocities v. */
void lc_contact_row_velocity(const lc_contact_row *r, const double *v, double *un, double *ut);

#endif
