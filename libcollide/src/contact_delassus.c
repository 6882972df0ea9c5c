/* The Delassus operator of a set of contact points (contact_delassus.h). */
#include "contact_delassus.h"

/* One Jacobian row: body indices, direction and lever arms. */
typedef struct jrow {
    int a, b;
    double dx, dy, ra, rb;
} jrow;

static jrow normal_of(const lc_contact_row *r)
{
    jrow j;
    j.a = r->a;
    j.b = r->b;
    j.dx = r->nx;
    j.dy = r->ny;
    j.ra = r->rna;
    j.rb = r->rnb;
    return j;
}

static jrow tangent_of(const lc_contact_row *r)
{
    jrow j;
    j.a = r->a;
    j.b = r->b;
    j.dx = -r->ny;
    j.dy = r->nx;
    j.ra = r->rta;
    j.rb = r->rtb;
    return j;
}

/* Entry of A = J M^-1 J^T between two Jacobian rows: the bodies they share. */
static double response(jrow p, jrow q, const double *inv_mass, const double *inv_inertia)
{
    double k = 0.0, dd = p.dx * q.dx + p.dy * q.dy;
    if (p.a >= 0 && p.a == q.a) k += inv_mass[p.a] * dd + inv_inertia[p.a] * p.ra * q.ra;
    if (p.a >= 0 && p.a == q.b) k -= inv_mass[p.a] * dd + inv_inertia[p.a] * p.ra * q.rb;
    if (p.b >= 0 && p.b == q.a) k -= inv_mass[p.b] * dd + inv_inertia[p.b] * p.rb * q.ra;
    if (p.b >= 0 && p.b == q.b) k += inv_mass[p.b] * dd + inv_inertia[p.b] * p.rb * q.rb;
    return k;
}

void lc_contact_delassus(const lc_contact_row *rows, int m, const double *inv_mass, const double *inv_inertia,
                         double *A)
{
    int i, j;
    for (i = 0; i < 2 * m; ++i)
        for (j = 0; j < 2 * m; ++j) {
            jrow pi = i < m ? normal_of(&rows[i]) : tangent_of(&rows[i - m]);
            jrow pj = j < m ? normal_of(&rows[j]) : tangent_of(&rows[j - m]);
            A[i * 2 * m + j] = response(pi, pj, inv_mass, inv_inertia);
        }
}
