/* The engine's fixed tunables, with why each is what it is. Settings a user may change are in
 * lc_world_def (types.h); these are not meant to be changed. */
#ifndef LC_TUNABLES_H
#define LC_TUNABLES_H

/* ---- the step (step.c) ----------------------------------------------------------------------- */

/* Tries of one step: after each, bodies whose actual paths met a body their island's build did not
 * pair them with (an impact threw one off its predicted path) get their islands grown to where they
 * went, and the step is taken again. Rare; the last try is kept. */
#define LC_MAX_ISLAND_TRIES 4

/* How much farther than its predicted path the island build looks around a body that rests on a
 * dissipative contact, as a fraction of its shortest edge: in a pile, contact impulses move a body off
 * the path its start velocity predicts (a box dropped at 8 m/s on a base-12 pyramid spread the rows
 * sideways by up to 3 mm a step), and a neighbour that then closes in unpaired costs the whole step
 * again. A twentieth of a 0.3-1 m box (15-50 mm) covers that; the price is a few more candidate pairs. */
#ifndef LC_ISLAND_MARGIN   /* -D to measure */
#define LC_ISLAND_MARGIN 0.05
#endif

/* Impacts of pairs that are not perfectly elastic the event regime resolves in one step before it hands
 * the island of the last one to the contact regime: a block bouncing ever lower at e < 1 makes
 * impacts without end when no speed threshold stops them (restitution_threshold and resting_speed
 * both 0), the inelastic collapse the contact regime exists for. A settling block makes a handful. */
#define LC_HANDOVER_EVENTS 8

/* ---- the broad phase (broad_phase.c) ---------------------------------------------------------- */

/* Bodies from which LC_BROADPHASE_AUTO finds the pairs from a grid (box_pairs.c) instead of a sweep
 * along x: the sweep visits the boxes in an x band, about sqrt(n) of them per box in a square world,
 * the grid a constant few, after a build of a few passes over the boxes. Instructions per body and
 * step of the scaling scene (bench/repro/probe_scaling.c, steps 0-30): sweep 4812 / grid 4937 at 2048
 * bodies, 5815 / 5754 at 4096. */
#define LC_GRID_MIN_ROWS 4096

/* ---- the event regime (event_regime.c, event_crossings.c, event_projection.c) ------------------ */

/* Most a body may turn (rad) within one collision-checked interval: vertex paths are tested as straight
 * lines in the other body's frame, which holds while bodies turn little, so a fast spinner is checked
 * over shorter trial intervals. */
#define LC_MAX_TRIAL_ROTATION 0.25
/* Event rows from which a trial interval's reach is tracked in a grid and the bodies keep lazy clocks
 * (event_regime.c): below it a visit of every body per impact costs less than the grid's build per
 * interval (20 seed blocks at g = 9.8: 22 % more per step with the grid, bench/repro/probe_seed.c). */
#define LC_TRACK_MIN_ROWS 64
/* Most rotation-limited intervals in one step: an absurd spin must not split the step without end (the
 * check is then coarser for that body). */
#define LC_MAX_TRIALS 1024
/* Most crossings one step may set aside as stalled (an impact at time 0 with nothing to do) before it
 * stops looking for crossings at all; the pass keeps them in a fixed array of this size (a sliver at
 * 1e6 m/s with damping 1e9 stalls 65; regression input
 * fuzz/corpus/step-regressions/stalled-list-overflow-65-stalled-crossings). */
#define LC_MAX_STALLED 64
/* Sub-times at which the swept check samples a pair whose paths may stray from their chords (a vertex
 * dipping into another body and out again within the interval, invisible to the end-point test); each
 * sample costs an integration of the pair, or of the world for a coupled pair. */
#define LC_SWEEP_SAMPLES 8
/* Passes of the end-of-step projection: the linearised rotation leaves a second-order remainder after a
 * deep correction (a sliver's corner millimetres in after an impact storm), and a few passes take it
 * below round-off. */
#define LC_PROJECTION_PASSES 16
/* Overlap (m) a step may end with: round-off of the projection. Deeper after every pass, the step fails
 * (forces far beyond what dt can resolve). */
#define LC_OVERLAP_TOLERANCE 1e-9

/* Most work one step may do before it is undone with LC_ERR_NUMERIC: force evaluations and serial
 * impulse passes. A 210-box pyramid needs ~30 evaluations per step and the seed scene none; these
 * are reached only by inputs such as a 1e6 kg and a 1e-300 kg body at 1e6 m/s, or a stiff spring
 * anchored 1e6 m away, which would otherwise spend seconds on one step before failing anyway. */
#ifndef LC_MAX_FORCE_EVALUATIONS_PER_STEP
#define LC_MAX_FORCE_EVALUATIONS_PER_STEP 500000
#endif
#ifndef LC_MAX_SERIAL_ITERATIONS_PER_STEP
#define LC_MAX_SERIAL_ITERATIONS_PER_STEP 50000
#endif
/* and the complementarity solves' work (lc_counters.solver_work), per body of the world: one force
 * evaluation of four coincident decagons (a 120-row dense group) costs 150 of the settling scene's
 * (20 blocks), so evaluations alone let such a step run 110 s to their cap (regression input
 * fuzz/corpus/step-regressions/slow-solver-work-coincident-tiny-decagons).
 * Measured per body (bench/repro/solver_work_per_body.py): the hardest legitimate step, a box dropped
 * onto a 78-box frictional pyramid, does 1.1e8 (10.5 s of CPU), the bench scenes at most 3e5; that
 * input did 1.7e10 by the evaluation cap, and now stops at 1e9 after 3 s. */
#ifndef LC_MAX_SOLVER_WORK_PER_BODY
#define LC_MAX_SOLVER_WORK_PER_BODY 1000000000
#endif
/* The caps can be lowered at build time (-DLC_MAX_...=N, a plain decimal number, which the step's
 * error messages quote): fuzz/run --engine-cap does so, so that the fuzzer does not spend seconds on
 * each input that ends at a cap anyway. */

/* ---- the contact regime (contact_regime.c) ---------------------------------------------------- */

/* Islands of at most this many bodies (a body on static ones) have their stick-slip transitions and
 * the arrivals of new contacts located in time (the step is cut there and solved again), as the event
 * regime locates impacts: a block sliding to a stop or into a wall is where a user sees the difference
 * (the stop distance v^2 / (2 mu g) exact instead of ~1e-3 off at dt 1/60). A cut costs one or two
 * solves of the island; in a pile transitions happen at every contact at different times, and cutting
 * at each (islands of up to 4 bodies: 10-30 cuts a step while 30 boxes settle) multiplied the step's
 * cost without a visible difference. */
#define LC_CONTACT_LOCATE_MAX_BODIES 1
/* Most cuts in one island's step; beyond them the rest of the step is taken whole. A rocking block
 * makes a few transitions per step; the cap bounds a pathological chatter. */
#define LC_CONTACT_MAX_CUTS 8
/* Most sub-steps a contact-regime island's step is taken in so that no body moves farther than its
 * own shortest edge in one (regime.h); an island that would need more stays in the event regime. */
#define LC_CONTACT_MAX_SUBSTEPS 16
/* A transition within this fraction of the step's end is left to the next step. */
#define LC_CONTACT_CUT_EPSILON 1e-9
/* m/s: a point that slips faster than this when a step begins gets friction only against its slip
 * (contact_solver.h), which keeps the friction's work over the step <= 0; slower, the whole cone
 * (static friction must hold a body at rest whose slip is round-off of either sign, ~1e-12 m/s). The
 * cone's work on such a point is at most mu lambda_n times this: 1e-9 J for a 1 kg body at dt 1/60
 * (resting_speed, 1e-4 m/s by default and up to 10, made it up to 7e-5 J in one step of a pile). */
#define LC_CONTACT_SLIP_SPEED 1e-6
/* m/s, the same for an island of several bodies (its first, not its precise, solve): there the points
 * of a settling pile slip to and fro at ~1 mm/s, and friction held to one side of its cone lets every
 * point that reverses within a step slide freely, so the pile does not come to rest. Below this the
 * whole cone acts; the work that can do beyond the one-sided rule (at most mu lambda_n times this per
 * point) is what the energy guard takes back from the island's motion (contact_regime.c). */
#define LC_CONTACT_PILE_SLIP_SPEED 1e-3
/* A solve of m points fewer than this may take contact_iterations x this / m sweeps: the work of one of
 * this size. A few bodies whose friction and normal impulses trade through their rotation need 40-60
 * sweeps where a large pile's warm-started solve needs a few; cut at contact_iterations, such an island
 * ended with its energy guard unmet and was taken again precisely (exactly, by pivoting: 70% of the CPU
 * of 30 boxes settling in a box). */
#define LC_CONTACT_SMALL_POINTS 64
/* A sub-step of an island of several bodies with fewer touches and speculative points than this
 * moves its positions by x += h v (Moreau-Jean) instead of the trapezoidal rule. Under the trapezoidal
 * rule a closed point that approaches must end separating as fast (its mean velocity keeps the gap),
 * so every approach the last solve left, however slow, takes an impact solve and a bounce re-solve
 * first: 40-60 % of the sweeps of 30 boxes settling in a box. With x += h v the flow stops such an
 * approach itself (u_n >= -(gap - contact_gap) / h at the end); the impact stage runs only for
 * approaches faster than resting_speed, which every regime reports as collisions. The rule is first
 * order, and loses 1/2 m g^2 h^2 per step to a body in free fall: it dissipates. It needs a converged
 * flow, since a velocity error moves positions twice as far as under the trapezoidal rule: below this
 * size the solves run to contact_tolerance (LC_CONTACT_SMALL_POINTS). In larger islands the sweeps
 * stall and the overlaps and projections that follow cost more than the impacts saved (mixed boxes,
 * bench/contact.py: 30 boxes -20, -66 and -5 % of instructions over three seeds, 100 boxes +8, -2 and
 * -4 % at this size and up to +35 % at 128 points, the block pushing a row of 40 +28 % at 128). An island
 * of one body keeps the trapezoidal rule, exact under constant forces (a block sliding to a stop at
 * v^2 / (2 mu g)). */
#define LC_CONTACT_MOREAU_JEAN_POINTS 64
/* A sub-step of an island of at least this many bodies, at least LC_CONTACT_MOREAU_JEAN_POINTS points
 * and fewer than LC_CONTACT_LARGE_ISLAND_BODIES bodies is a pile sub-step: one solve, the flow, whose
 * targets hold the impacts' Newton restitution (a point touching or arriving in the step's first half
 * that approaches faster than the bounce speed must leave at e times its approach), positions by
 * x += h v, and the large islands' projection slack (LC_CONTACT_PROJECTION_LARGE_SLACK). In such a pile
 * Gauss-Seidel stalls: 100 mixed boxes piled in a box end their 200-point flow 1e-2 m/s from its answer
 * after 30 sweeps, with 40-60 points still changing by 1e-3 m/s. The trapezoidal path's impact solves
 * (a compression and a second compression after the bounce, run at every step where any closed point
 * approaches) cannot converge either and only triple the sweeps, and projecting the overlaps those
 * velocities leave (1e-4 m a step) to 4e-10 m took two passes of 50 sweeps. Instructions per step
 * (callgrind, 300 steps of bench/contact.py's scenes) against the trapezoidal path: 100 mixed boxes -29,
 * -40 and -32 % over three seeds, a box dropped on a base-12 pyramid -41 %, the block pushing a row of
 * 40 -11 %, the base-20 pyramid -8 % (with the projection's start of LC_CONTACT_PROJECTION_LARGE). Islands of LC_CONTACT_LARGE_ISLAND_BODIES bodies or more keep the
 * trapezoidal path: a velocity error moves positions twice as far under x += h v, and the settled
 * 1 000-box pile's projection (active sets and MPRGP) then took +23 % of a step. Fewer bodies than this
 * (a few polygons with many vertices) converge, and keep the exact impacts and the 4e-10 m slack. */
#define LC_CONTACT_PILE_BODIES 16
/* The flow's solve (step 3) of an island of LC_CONTACT_PILE_BODIES bodies or more (outside a settling
 * sub-step or a precise retry) whose mass-weighted rms speed is below |g| dt (16 cm/s at dt 1/60), and
 * that has not met contact_tolerance in its sweeps, goes on until its largest change (m/s) is at most
 * this fraction of that speed, for LC_CONTACT_PILE_FLOW_SWEEPS sweeps in all at most (the stall rule
 * still applies). Such a pile moves slower than gravity changes a velocity in one step: its contacts
 * carry most of its weight every step, and cut at 30 sweeps their impulses keep an error the size of its
 * motion. Its friction then holds too little, boxes slide off one another and the pile flows on, a slow
 * avalanche: 100 mixed boxes at 3-37 cm/s rms from 4 s to 11 s (bench/scenes.py mixed_boxes, seed 5;
 * Box2D v3's pile of that scene rests by 6 s; tests/python/test_pile_comes_to_rest.py), 1 000 boxes
 * moving 0.2-0.5 m in every second up to 12 s (seed 2). A falling pile keeps the cheap cut-off: its error
 * is small beside its motion. So does a pile at small steps (the node's 1 ms: below 1 cm/s it settles),
 * where going on cost more and the 200-box piles of bench/node_bench.py came to rest 0.5-0.75 s later;
 * and the impact stage's solves, which stop approaches rather than hold weight (going on there too cost
 * a settling 1 000-box pile up to 115 ms a step, against 60-90 ms). */
#ifndef LC_CONTACT_PILE_FLOW_FRACTION   /* -D to measure */
#define LC_CONTACT_PILE_FLOW_FRACTION 0.1
#endif
#ifndef LC_CONTACT_PILE_FLOW_SWEEPS   /* -D to measure */
#define LC_CONTACT_PILE_FLOW_SWEEPS 100
#endif
/* When a contact-regime step ends with an overlap it cannot project away or an energy gain the island's
 * kinetic energy cannot pay (a nearly resting island whose solves stopped at contact_iterations, 1e-4
 * to 5e-3 m/s off), the step is taken again with solves of up to this many sweeps and exact ones up to
 * this many points (a 16-point problem: ~40 pivots, where the sweeps need 100-700). */
#define LC_CONTACT_PRECISE_SWEEPS 1000
/* A sub-step of an island of at least LC_CONTACT_SETTLE_BODIES bodies whose mass-weighted rms speed is
 * below LC_CONTACT_SETTLE_SPEED (m/s) when it begins is a settling sub-step. Its solves run up to
 * LC_CONTACT_SETTLE_SWEEPS sweeps, to LC_CONTACT_SETTLE_TOLERANCE (m/s, or contact_tolerance if larger),
 * or until a sweep changes no body's velocity component by more than LC_CONTACT_SETTLE_BODY_TOLERANCE
 * (m/s); the stall rule applies only below LC_CONTACT_REST_SPEED (contact_solver.h, lc_contact_stop).
 * A pile's solve stopped by the stall rule or at contact_iterations is 1e-2 to 1e-1 m/s off; that error
 * drives its bodies into each other every step, the projection pushes them apart, and such a pile never
 * came to rest (100 mixed boxes: the median box still moved 1-5 mm a second after 8 s). Converged, six
 * of seven such piles rest by 4-9 s (bench/repro/pile_rest.py); once still, a pile is not solved
 * (contact_regime.c, hold_still). Above the speed, a falling pile's solves keep their cheap cut-off: what they
 * leave is small beside its motion. The body rule: a pile's impulses are not unique, and Gauss-Seidel
 * trades them between rows sweep after sweep (its largest change stays at 1e-5 m/s in a resting
 * 1 000-box pile) at velocities that no longer move. */
#define LC_CONTACT_SETTLE_BODIES 16
#ifndef LC_CONTACT_SETTLE_SPEED   /* -D to measure */
#define LC_CONTACT_SETTLE_SPEED 1e-2
#endif
#ifndef LC_CONTACT_SETTLE_SWEEPS   /* -D to measure */
#define LC_CONTACT_SETTLE_SWEEPS 1000
#endif
#ifndef LC_CONTACT_SETTLE_TOLERANCE   /* -D to measure */
#define LC_CONTACT_SETTLE_TOLERANCE 1e-6
#endif
#ifndef LC_CONTACT_SETTLE_BODY_TOLERANCE   /* -D to measure */
#define LC_CONTACT_SETTLE_BODY_TOLERANCE 1e-7
#endif
/* m/s: a settling sub-step of an island that nothing but gravity and contacts drives, whose answer moves
 * no body's point (centre speed plus |omega| times its radius) faster than this, is rest: the velocities
 * are set to 0 before the positions move. Below this the answer is the solve's own error; moved by it,
 * a resting pyramid sank ~2e-8 m a step until its projection lifted it back in one step, with more
 * potential energy than its kinetic energy could pay (a box dropped on a base-15 pyramid kept 2e-5 J,
 * 3e-9 of the world's energy, in such a step). Rest only removes kinetic energy. It holds still a body
 * that its resting pile would start with less than this speed in a step (an acceleration below
 * 6e-4 m/s^2 at dt 1/60, a frictionless slope under 6e-5 rad); a driven island (thruster, external
 * force, spring, force callback) is never held. */
#ifndef LC_CONTACT_REST_SPEED   /* -D to measure */
#define LC_CONTACT_REST_SPEED 1e-5
#endif
/* m/s: an undriven island of more than LC_CONTACT_EVENT_FALLBACK_BODIES bodies none of whose bodies'
 * points moved this fast when the step began, and whose step no try could take without an overlap or a
 * gain its kinetic energy could not pay (lc_contact_advance), is held at rest for the step: its
 * velocities become 0 and its state stays. Such a pile is resting but for its solves' error: they end a
 * few 1e-6 m/s off, that drives bodies into each other, and the projection lifts them higher than they
 * sank (a box dropped on a base-17 pyramid: 2.4e-5 J kept, 2.4e-9 of the world's energy, from 1.9e-5 m/s
 * at most). Held, it loses at most its kinetic energy and a step's travel at this speed (1.7e-6 m at dt
 * 1/60). */
#ifndef LC_CONTACT_HOLD_SPEED   /* -D to measure */
#define LC_CONTACT_HOLD_SPEED 1e-4
#endif
/* Pivots the exact solver may take per unknown before it gives up (Lemke's pivoting cycles only on
 * degenerate ties, which the lexicographic rule breaks; the cap is a guard). */
#define LC_LEMKE_PIVOTS_PER_UNKNOWN 20
/* Rounds of the active-set solve (contact_exact.h) before it gives up: from a stalled Gauss-Seidel answer
 * a few points change side in the first rounds and the set settles in 2-4 rounds. */
#define LC_CONTACT_ACTIVE_SET_ITERATIONS 16
/* Refinements of an active-set solve against the unregularized equations: each takes the error the
 * 1e-10 regularization left down by that factor again. */
#define LC_CONTACT_ACTIVE_SET_REFINEMENTS 2
#ifndef LC_CONTACT_PRECISE_EXACT_POINTS
#define LC_CONTACT_PRECISE_EXACT_POINTS 32
#endif
/* Islands of at most this many bodies whose contact-regime step, precise too, leaves an overlap or an
 * energy gain above the allowances below are taken again in the event regime, exact at that size. A
 * larger island keeps the precise step and counts it (lc_counters contact_unresolved): the event
 * regime's cost grows with the cube of an island's contacts at each micro-impact (a base-12 pyramid
 * hit by a box: seconds for one step), and the gain such a step keeps is what its precise solve left,
 * ~1e-10 of the island's energy in that pyramid (bench/contact.py's drop12). */
#define LC_CONTACT_EVENT_FALLBACK_BODIES 8
/* Sub-steps of the last retry of such a larger island before it keeps its step: a nearly resting
 * island's unconverged velocities carry its bodies into each other over a step, and the projection
 * lifts them out higher than they sank; over a quarter of the step they drift a quarter as far (a box
 * dropped on a base-12 pyramid, on a trajectory of bench/contact.py drop12's scene: a resting
 * pyramid's precise step kept 6.6e-6 J, 2e-9 of the island's energy; in 2 sub-steps 2.6e-6 J; in 4 it
 * met the allowance). */
#define LC_CONTACT_SPLIT_SUBSTEPS 4
/* Sweeps over which a contact solve's largest change must halve, or the solve stops as stalled (a
 * precise retry runs its sweeps out). */
#ifndef LC_CONTACT_STALL_SWEEPS   /* -D to measure */
#define LC_CONTACT_STALL_SWEEPS 32
#endif
/* m, the gap the position projection moves an overlapping point out to (and the overlap that starts
 * it): a tenth of the 1e-9 m overlap the test suites allow at a step's end, far below what a lift
 * costs in energy (1e-9 J per kg). contact_gap / 1000 where that is smaller. */
#define LC_CONTACT_PROJECTION_GAP 1e-10
/* m, how far from that aim the projection's solve may stop, and the overlap that starts it: it then
 * leaves at most this (to first order; the passes catch the rest) of the 1e-9 m allowed. Solving a
 * pile's micrometre correction to 1e-11 m instead took MPRGP hundreds of products every step. */
#ifndef LC_CONTACT_PROJECTION_SLACK
#define LC_CONTACT_PROJECTION_SLACK 4e-10
#endif
/* m, the projection's slack in an island of at least LC_CONTACT_LARGE_ISLAND_BODIES bodies and in a pile
 * sub-step (LC_CONTACT_PILE_BODIES): a pile that
 * large settles with its flow a millimetre deep every step (Gauss-Seidel stalls in its height), and
 * projecting that to 4e-10 m took the passes' second and third solves, a third of such a step's
 * instructions (a settling 1 000-box pile, callgrind); 1e-7 m is ten times inside the 1e-6 m the contact
 * scenes are held to (bench/contact.py), and 1e-6 m of lift is 1e-5 J per kilogram at g. */
#define LC_CONTACT_PROJECTION_LARGE_SLACK 1e-7
#define LC_CONTACT_LARGE_ISLAND_BODIES 300
/* m, the overlap a contact-regime step may leave after its projection before the island is taken again
 * (contact_regime.c): the test suites' 1e-9 m, ten times the projection's own aim; in a large island or
 * a pile sub-step scaled with its slack (2.5e-7 m, four times inside the 1e-6 m the contact scenes are
 * held to). */
#define LC_CONTACT_OVERLAP_LEFT 1e-9
/* The energy gain, relative to an island's energy (the sum of its terms' magnitudes), a contact-regime
 * step may leave when the island's kinetic energy cannot pay for it before the island is taken again
 * in the event regime: ten times below the 1e-9 of a step's total energy that the contact scenes are
 * held to (bench/contact.py), far above round-off (1e-14). */
#define LC_CONTACT_ENERGY_LEFT 1e-10
/* Passes of the position projection: each solves the linearised gaps, the nonlinear remainder of a
 * rotation is second order and vanishes in a few. */
#define LC_CONTACT_PROJECTION_PASSES 8
/* Sweeps of each projection pass's Gauss-Seidel; when they do not converge, the pass is solved by MPRGP
 * with at most LC_CONTACT_PROJECTION_PRODUCTS products of the response (a chain or stack of n bodies
 * needs ~n^2 sweeps, ~n products). */
#define LC_CONTACT_PROJECTION_SWEEPS 50
#ifndef LC_CONTACT_PROJECTION_GAIN
#define LC_CONTACT_PROJECTION_GAIN 1e-2
#endif
#define LC_CONTACT_PROJECTION_PRODUCTS 2000
/* A projection pass of at least LC_CONTACT_PROJECTION_LARGE points, or of a pile sub-step
 * (LC_CONTACT_PILE_BODIES), that Gauss-Seidel did not converge starts MPRGP from the sweeps' answer and stops it within LC_CONTACT_PROJECTION_PASS_TOLERANCE of the
 * overlap the pass starts from (or at LC_CONTACT_PROJECTION_SLACK, the larger): the linearised gaps a
 * pass solves are off by the rotation's second-order remainder, ~overlap^2 / size (3e-3 of a
 * millimetre's overlap on a 0.3 m box), which the next pass removes together with the solve's own
 * error. A settling 1 000-box pile ends its flow a millimetre deep every step (Gauss-Seidel stalls in
 * its 25 layers); its passes took the 2 000-product budget and 600 more to reach 4e-10 m from zero.
 * A pile sub-step's velocities move its bodies into each other by x += h v: 1 000 boxes landing in a box
 * form islands of 16-299 bodies whose passes, from zero to the slack, took MPRGP 3.5 times the
 * instructions (callgrind, steps 50-100 of bench/contact.py's mixed1000, +58 % a step); from the sweeps'
 * answer the step costs what the trapezoidal path's did, and the box dropped on a base-12 pyramid takes
 * 12 % fewer instructions with no step kept unresolved. Other passes start from zero and keep the
 * absolute stop: their products are cheap, and either change moved which steps of that drop needed their
 * precise retry under the trapezoidal path, one of them then keeping a gain above 1e-9 of the energy. */
#define LC_CONTACT_PROJECTION_PASS_TOLERANCE 1e-3
#define LC_CONTACT_PROJECTION_LARGE 1000
/* A projection pass of at least this many points starts from active sets over a sparse factorization
 * (projection_active_set.h), whose cost does not grow with a pile's height; below it the sweeps usually
 * converge and cost less (from 256 points up, a box dropped on a base-12 pyramid took 20 % more
 * instructions and one step kept an energy gain of 1.2e-9, bench/contact.py drop12). */
#ifndef LC_CONTACT_PROJECTION_DIRECT_ROWS   /* -D to measure */
#define LC_CONTACT_PROJECTION_DIRECT_ROWS 1000
#endif

/* ---- contact forces and impulses (contact_forces.c, impulse.c) ---------------------------------- */

/* The force tolerance of a group in motion (contact_forces.c, group_tolerance; a group whose touches
 * all move slower than 10 resting_speed keeps its tight tolerance, which is what keeps a resting pile
 * from creeping over minutes): 1e-4 of its fastest touch's speed per step (v / h), so that a force error
 * moves a point by at most 5e-5 of the distance that touch covers in the step, but never looser
 * than 1e-3 of gravity's acceleration (no loosening at g = 0).
 * Why: in a pile in motion the tight tolerance cost the budget of every solve (MPRGP's normal rows
 * stalled at 1e-6-1e-3 m/s^2 after 1 000 products, the rows between side-by-side boxes the
 * slowest); a 5 kg box dropped into a frictional base-12 pyramid (bench/repro/drop_into_pyramid.py)
 * was undone at the serial cap in step 12, and goes through its first 20 steps in 51 s of CPU with
 * this (34 s without the ceiling, 70 s with a ceiling of 10 contact_gap / h^2).
 * The speed threshold keeps a slow creep (a frictionless pile drifting at 1e-6 m/s) from loosening
 * its own tolerance: at 1 cm/s the pile's slow settling after that impact took 820 s, at 1 mm/s
 * 161 s. The ceiling bounds what a fast body can loosen: a 1e-11 m sliver at 1e6 m/s (dt 1e-3)
 * made the tolerance 1e5 m/s^2 and a step ran to LC_MAX_FORCE_EVALUATIONS_PER_STEP (regression input
 * fuzz/corpus/step-regressions/slow-motion-tolerance-fast-sliver-exact-max-0); with the ceiling
 * the input takes 0.08 s. */
#define LC_MOTION_TOLERANCE 1e-4
#define LC_MOTION_TOLERANCE_CEILING 1e-3
/* Most alternations between the normal and the friction rows of a small group (contact_forces.c). */
#define LC_FRICTION_ROUNDS_SMALL 8
/* Most alternations between the normal and the friction rows of a large group (contact_forces.c). */
#define LC_FRICTION_ROUNDS 4
/* The alternation stops when a round's change grows to this multiple of the previous one's: it is not
 * converging, and more rounds would only cost solves. */
#define LC_FRICTION_STALL 1.5
/* Most alternations between the normal and the friction rows of a large impact (impulse.c). */
#define LC_IMPULSE_FRICTION_ROUNDS 4

/* ---- the sparse solver and its starting guesses (sparse_lcp.c, static_load.c) ------------------- */

/* Proportioning constant: release bound rows when their chopped gradient outweighs the free one. */
#define LC_MPRGP_GAMMA 1.0
/* Power iterations that estimate ||A|| for the expansion step length: from scratch, and when the
 * previous solve had as many rows (the same pile a moment later). Then its estimate is used as it is
 * and refreshed (kept if larger) only before the solve's first expansion step, the one place a low
 * estimate could do harm: a warm-started pile's solve usually takes none, and the refresh was 6 of
 * its 10 products. */
#define LC_MPRGP_POWER_ITERATIONS 12
#define LC_MPRGP_POWER_REFRESH 3
/* A solve whose violation rises to this multiple of the kept iterate's has diverged: it stops and
 * returns the kept iterate (one that came within 2x of the best violation so far).
 * Why: MPRGP lowers the objective at every step, but only in exact arithmetic. A 5e-12 m decagon
 * with a wall corner's touch 3e4 m from its centre (inverse inertia 8.6e21) gave its group
 * ||A|| ~ 1e28 against a smallest scale ~0.1: past round-off, the expansion steps grew the
 * violation to 1e28-1e153 m/s^2 in every solve until the budget, and one step took 142 s to reach
 * the evaluation cap (regression input
 * fuzz/corpus/step-regressions/slow-solver-diverged-tiny-polygon-exact-max-0; 0.01 s with this).
 * The violation of a sound solve is not
 * monotone either: in the seven scenes of bench/repro/same_bits.c (790 000 solves) it rose up to
 * 1e5-1e6 times above its best, and a threshold of 1e5 changes the settling scene's state hash;
 * at 1e6, and at 1e8, 100x above that, every hash is the one of the solver without the check. */
#ifndef LC_MPRGP_DIVERGED   /* -D to measure that margin */
#define LC_MPRGP_DIVERGED 1e8
#endif
/* cos 60 degrees: steeper touches (walls, the sides of boxes) carry no guessed load (static_load.c) */
#define LC_SUPPORT_COS 0.5

#endif
