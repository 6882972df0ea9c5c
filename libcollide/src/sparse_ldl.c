/* Sparse LDL^T by geometric nested dissection and up-looking factorization (sparse_ldl.h). */
#include <stdlib.h>
#include <string.h>
#include "sparse_ldl.h"
#include "world.h"

/* Segments of at most this many rows are not split further: below it a separator saves less fill than
 * the split costs. */
#define LDL_LEAF_ROWS 32

struct lc_sparse_ldl {
    int n, nelem;
    /* ordering: perm (position -> row), each row's elements, each element's rows (CSR), the dissection's
     * scratch */
    lc_buf b_perm, b_elem, b_eptr, b_erows, b_side, b_seg, b_cnt, b_key;
    /* the matrix of every row, its upper triangle by columns in the order's positions (fp, fi, fx) */
    lc_buf b_pos, b_fp, b_fi, b_fx;
    /* factor over the m active rows, in their order: inv (index -> row), q (row -> index or -1), A's upper
     * triangle by columns (ap, ai, ax), its diagonal, the elimination tree, L (lp, lnz, li, lx), D, and the
     * numeric scratch (y, pattern, flag) */
    int m;
    long entries;
    lc_buf b_inv, b_q, b_ap, b_ai, b_ax, b_diag, b_parent, b_lp, b_lnz, b_li, b_lx, b_d, b_y, b_pattern, b_flag;
};

lc_sparse_ldl *lc_sparse_ldl_create(void) { return calloc(1, sizeof(lc_sparse_ldl)); }

void lc_sparse_ldl_destroy(lc_sparse_ldl *f)
{
    if (f == NULL) return;
    lc_buf_free(&f->b_perm); lc_buf_free(&f->b_elem); lc_buf_free(&f->b_eptr); lc_buf_free(&f->b_erows);
    lc_buf_free(&f->b_side); lc_buf_free(&f->b_seg); lc_buf_free(&f->b_cnt); lc_buf_free(&f->b_key);
    lc_buf_free(&f->b_pos); lc_buf_free(&f->b_fp); lc_buf_free(&f->b_fi); lc_buf_free(&f->b_fx);
    lc_buf_free(&f->b_inv); lc_buf_free(&f->b_q); lc_buf_free(&f->b_ap); lc_buf_free(&f->b_ai);
    lc_buf_free(&f->b_ax); lc_buf_free(&f->b_diag); lc_buf_free(&f->b_parent); lc_buf_free(&f->b_lp);
    lc_buf_free(&f->b_lnz); lc_buf_free(&f->b_li); lc_buf_free(&f->b_lx); lc_buf_free(&f->b_d);
    lc_buf_free(&f->b_y); lc_buf_free(&f->b_pattern); lc_buf_free(&f->b_flag);
    free(f);
}

/* ---- ordering ---------------------------------------------------------------------------------- */

typedef struct keyed { double key; int id; } keyed;

static int before(const keyed *a, const keyed *b)
{
    return a->key < b->key || (a->key == b->key && a->id < b->id);   /* ties by row: one order everywhere */
}

static void swap_keyed(keyed *a, keyed *b)
{
    keyed t = *a;
    *a = *b;
    *b = t;
}

/* Puts the k-th smallest of key[0..n) at k, the smaller before it and the larger after (Hoare's
 * selection, median-of-three pivots): the split needs the median, not a sorted order. */
static void select_kth(keyed *key, int n, int k)
{
    int lo = 0, hi = n - 1;
    while (hi > lo) {
        int mid = lo + (hi - lo) / 2, i = lo, j = hi;
        keyed pivot;
        if (before(&key[mid], &key[lo])) swap_keyed(&key[mid], &key[lo]);
        if (before(&key[hi], &key[lo])) swap_keyed(&key[hi], &key[lo]);
        if (before(&key[hi], &key[mid])) swap_keyed(&key[hi], &key[mid]);
        pivot = key[mid];
        while (i <= j) {
            /* bounded: a NaN coordinate compares neither way, and must not walk a scan off the range */
            while (i < hi && before(&key[i], &pivot)) ++i;
            while (j > lo && before(&pivot, &key[j])) --j;
            if (i <= j) {
                swap_keyed(&key[i], &key[j]);
                ++i;
                --j;
            }
        }
        if (k <= j) hi = j;
        else if (k >= i) lo = i;
        else return;
    }
}

typedef struct dissection {
    const double *xy;
    const int *elem, *eptr, *erows;
    int *side, *seg, *cnt;   /* per row: side (0, 1, 2 = separator), segment stamp; per element: counts */
    keyed *key;
    int stamp;
} dissection;

/* Orders ids[0..n) in place: both halves recursively, then their separator. */
static void dissect(dissection *d, int *ids, int n)
{
    double x0, x1, y0, y1;
    int i, k, axis, half, nl, nr, ns, stamp;
    if (n <= LDL_LEAF_ROWS) return;
    x0 = x1 = d->xy[2 * ids[0]];
    y0 = y1 = d->xy[2 * ids[0] + 1];
    for (i = 1; i < n; ++i) {
        double x = d->xy[2 * ids[i]], y = d->xy[2 * ids[i] + 1];
        x0 = x < x0 ? x : x0; x1 = x > x1 ? x : x1;
        y0 = y < y0 ? y : y0; y1 = y > y1 ? y : y1;
    }
    axis = (y1 - y0) > (x1 - x0) ? 1 : 0;
    for (i = 0; i < n; ++i) {
        d->key[i].key = d->xy[2 * ids[i] + axis];
        d->key[i].id = ids[i];
    }
    half = n / 2;
    select_kth(d->key, n, half);
    stamp = ++d->stamp;
    for (i = 0; i < n; ++i) {
        int r = d->key[i].id;
        ids[i] = r;
        d->side[r] = i < half ? 0 : 1;
        d->seg[r] = stamp;
        for (k = 0; k < 2; ++k)
            if (d->elem[2 * r + k] >= 0) d->cnt[2 * d->elem[2 * r + k]] = d->cnt[2 * d->elem[2 * r + k] + 1] = 0;
    }
    for (i = 0; i < n; ++i)
        for (k = 0; k < 2; ++k) {
            int e = d->elem[2 * ids[i] + k];
            if (e >= 0) d->cnt[2 * e + d->side[ids[i]]]++;
        }
    /* an element with rows on both sides couples them: its rows on the side where it has fewer go to the
     * separator (and leave their other element's count there) */
    for (i = 0; i < n; ++i)
        for (k = 0; k < 2; ++k) {
            int e = d->elem[2 * ids[i] + k], s, p;
            if (e < 0 || d->cnt[2 * e] == 0 || d->cnt[2 * e + 1] == 0) continue;
            s = d->cnt[2 * e] <= d->cnt[2 * e + 1] ? 0 : 1;
            for (p = d->eptr[e]; p < d->eptr[e + 1]; ++p) {
                int r = d->erows[p], j;
                if (d->seg[r] != stamp || d->side[r] != s) continue;
                d->side[r] = 2;
                for (j = 0; j < 2; ++j)
                    if (d->elem[2 * r + j] >= 0) d->cnt[2 * d->elem[2 * r + j] + s]--;
            }
        }
    /* ids as [left | right | separator] */
    nl = nr = ns = 0;
    for (i = 0; i < n; ++i) {
        int r = d->key[i].id;
        if (d->side[r] == 0) ids[nl++] = r;
    }
    for (i = 0; i < n; ++i) {
        int r = d->key[i].id;
        if (d->side[r] == 1) ids[nl + nr++] = r;
    }
    for (i = 0; i < n; ++i) {
        int r = d->key[i].id;
        if (d->side[r] == 2) ids[nl + nr + ns++] = r;
    }
    /* a split that separated nothing (every row in one element's clique) ends the recursion */
    if (nl == 0 || nr == 0) return;
    dissect(d, ids, nl);
    dissect(d, ids + nl, nr);
}

int lc_sparse_ldl_order(lc_sparse_ldl *f, int n, const double *xy, const int *elem, int nelem)
{
    dissection d;
    int *perm, *eptr, *erows, *el, i, k;
    size_t nn = (size_t)(n > 0 ? n : 1), ne = (size_t)(nelem > 0 ? nelem : 1);
    f->n = n;
    f->nelem = nelem;
    perm = lc_buf_get(&f->b_perm, nn * sizeof(int));
    el = lc_buf_get(&f->b_elem, 2 * nn * sizeof(int));
    eptr = lc_buf_get(&f->b_eptr, (ne + 1) * sizeof(int));
    erows = lc_buf_get(&f->b_erows, 2 * nn * sizeof(int));
    d.side = lc_buf_get(&f->b_side, nn * sizeof(int));
    d.seg = lc_buf_get(&f->b_seg, nn * sizeof(int));
    d.cnt = lc_buf_get(&f->b_cnt, 2 * ne * sizeof(int));
    d.key = lc_buf_get(&f->b_key, nn * sizeof(keyed));
    if (perm == NULL || el == NULL || eptr == NULL || erows == NULL || d.side == NULL || d.seg == NULL ||
        d.cnt == NULL || d.key == NULL)
        return -1;
    memcpy(el, elem, 2 * (size_t)n * sizeof(int));
    for (i = 0; i <= nelem; ++i) eptr[i] = 0;
    for (i = 0; i < 2 * n; ++i)
        if (el[i] >= 0) eptr[el[i] + 1]++;
    for (i = 0; i < nelem; ++i) eptr[i + 1] += eptr[i];
    for (i = 0; i < nelem; ++i) d.cnt[i] = eptr[i];   /* fill positions */
    for (i = 0; i < n; ++i)
        for (k = 0; k < 2; ++k)
            if (el[2 * i + k] >= 0) erows[d.cnt[el[2 * i + k]]++] = i;
    for (i = 0; i < n; ++i) {
        perm[i] = i;
        d.seg[i] = 0;
    }
    d.xy = xy;
    d.elem = el;
    d.eptr = eptr;
    d.erows = erows;
    d.stamp = 0;
    if (n > 0) dissect(&d, perm, n);
    return 0;
}

/* ---- factorization ----------------------------------------------------------------------------- */

/* Sums repeated entries of the columns (ap, ai, ax) of m columns in place; pattern: m ints of scratch. */
static void compact_columns(int m, int *ap, int *ai, double *ax, int *pattern)
{
    int k, p, w = 0;
    for (k = 0; k < m; ++k) pattern[k] = -1;   /* a row's slot in the column being compacted */
    for (k = 0; k < m; ++k) {
        int start = w, end = ap[k + 1];
        for (p = ap[k]; p < end; ++p) {
            int r = ai[p];
            if (pattern[r] >= start) {
                ax[pattern[r]] += ax[p];
            } else {
                pattern[r] = w;
                ai[w] = r;
                ax[w++] = ax[p];
            }
        }
        ap[k] = start;
    }
    ap[m] = w;
}

int lc_sparse_ldl_matrix(lc_sparse_ldl *f, int nz, const int *ti, const int *tj, const double *tv)
{
    int n = f->n, k, p;
    size_t nn = (size_t)(n > 0 ? n : 1), nzz = (size_t)(nz > 0 ? nz : 1);
    const int *perm = f->b_perm.p;
    int *pos = lc_buf_get(&f->b_pos, nn * sizeof(int)), *fp = lc_buf_get(&f->b_fp, (nn + 1) * sizeof(int));
    int *fi = lc_buf_get(&f->b_fi, nzz * sizeof(int)), *fill = lc_buf_get(&f->b_flag, nn * sizeof(int));
    double *fx = lc_buf_get(&f->b_fx, nzz * sizeof(double));
    if (pos == NULL || fp == NULL || fi == NULL || fill == NULL || fx == NULL) return -1;
    for (k = 0; k < n; ++k) pos[perm[k]] = k;
    for (k = 0; k <= n; ++k) fp[k] = 0;
    for (p = 0; p < nz; ++p) {
        int a = pos[ti[p]], b = pos[tj[p]];
        fp[(a > b ? a : b) + 1]++;
    }
    for (k = 0; k < n; ++k) fp[k + 1] += fp[k];
    for (k = 0; k < n; ++k) fill[k] = fp[k];
    for (p = 0; p < nz; ++p) {
        int a = pos[ti[p]], b = pos[tj[p]], c = a > b ? a : b;
        fi[fill[c]] = a < b ? a : b;
        fx[fill[c]++] = tv[p];
    }
    compact_columns(n, fp, fi, fx, fill);
    return 0;
}

int lc_sparse_ldl_factor(lc_sparse_ldl *f, const unsigned char *active, const double *add, double min_pivot)
{
    int n = f->n, m = 0, i, k, p;
    const int *perm = f->b_perm.p, *fp = f->b_fp.p, *fi = f->b_fi.p;
    const double *fx = f->b_fx.p;
    size_t nn = (size_t)(n > 0 ? n : 1), nzz = (size_t)(n > 0 ? fp[n] : 0) + 1;
    int *inv = lc_buf_get(&f->b_inv, nn * sizeof(int)), *q = lc_buf_get(&f->b_q, nn * sizeof(int));
    int *ap = lc_buf_get(&f->b_ap, (nn + 1) * sizeof(int)), *ai = lc_buf_get(&f->b_ai, nzz * sizeof(int));
    double *ax = lc_buf_get(&f->b_ax, nzz * sizeof(double)), *diag = lc_buf_get(&f->b_diag, nn * sizeof(double));
    int *parent = lc_buf_get(&f->b_parent, nn * sizeof(int)), *lp = lc_buf_get(&f->b_lp, (nn + 1) * sizeof(int));
    int *lnz = lc_buf_get(&f->b_lnz, nn * sizeof(int)), *pattern = lc_buf_get(&f->b_pattern, nn * sizeof(int));
    int *flag = lc_buf_get(&f->b_flag, nn * sizeof(int)), *li;
    double *y = lc_buf_get(&f->b_y, nn * sizeof(double)), *lx, *dd = lc_buf_get(&f->b_d, nn * sizeof(double));
    long total;
    if (inv == NULL || q == NULL || ap == NULL || ai == NULL || ax == NULL || diag == NULL || parent == NULL ||
        lp == NULL || lnz == NULL || pattern == NULL || flag == NULL || y == NULL || dd == NULL)
        return -1;
    /* the active rows' columns of the whole matrix, renumbered: positions keep their order */
    for (k = 0; k < n; ++k) {
        q[k] = active[perm[k]] ? m : -1;
        if (active[perm[k]]) inv[m++] = perm[k];
    }
    f->m = m;
    ap[0] = 0;
    for (k = 0, i = 0; k < n; ++k) {
        if (q[k] < 0) continue;
        for (p = fp[k]; p < fp[k + 1]; ++p)
            if (q[fi[p]] >= 0) {
                ai[i] = q[fi[p]];
                ax[i++] = fx[p] + (fi[p] == k && add != NULL ? add[perm[k]] : 0.0);
            }
        ap[q[k] + 1] = i;
    }
    /* the elimination tree and the column counts of L, by the walk the factorization repeats */
    for (k = 0; k < m; ++k) {
        parent[k] = -1;
        flag[k] = k;
        lnz[k] = 0;
        diag[k] = 0.0;
        for (p = ap[k]; p < ap[k + 1]; ++p) {
            i = ai[p];
            if (i == k) diag[k] += ax[p];
            for (; flag[i] != k; i = parent[i]) {
                if (parent[i] == -1) parent[i] = k;
                lnz[i]++;
                flag[i] = k;
            }
        }
    }
    lp[0] = 0;
    for (k = 0; k < m; ++k) lp[k + 1] = lp[k] + lnz[k];
    total = lp[m];
    f->entries = total;
    li = lc_buf_get(&f->b_li, (size_t)(total > 0 ? total : 1) * sizeof(int));
    lx = lc_buf_get(&f->b_lx, (size_t)(total > 0 ? total : 1) * sizeof(double));
    if (li == NULL || lx == NULL) return -1;
    /* row k of L: the sparse triangular solve L(0:k,0:k) D y = A(0:k,k) over the reach of column k */
    for (k = 0; k < m; ++k) {
        int top = m;
        double dk;
        y[k] = 0.0;
        flag[k] = k;
        lnz[k] = 0;
        for (p = ap[k]; p < ap[k + 1]; ++p) {
            int len = 0;
            i = ai[p];
            y[i] += ax[p];
            for (; flag[i] != k; i = parent[i]) {
                pattern[len++] = i;
                flag[i] = k;
            }
            while (len > 0) pattern[--top] = pattern[--len];
        }
        dk = y[k];
        y[k] = 0.0;
        for (; top < m; ++top) {
            int j = pattern[top], end = lp[j] + lnz[j];
            double yj = y[j], l;
            y[j] = 0.0;
            for (p = lp[j]; p < end; ++p) y[li[p]] -= lx[p] * yj;
            l = yj / dd[j];
            dk -= l * yj;
            li[end] = k;
            lx[end] = l;
            lnz[j]++;
        }
        if (!(dk > min_pivot * diag[k])) dk = diag[k] > 0.0 ? min_pivot * diag[k] : 1.0;
        dd[k] = dk;
    }
    return 0;
}

void lc_sparse_ldl_solve(const lc_sparse_ldl *f, double *x)
{
    int m = f->m, j, p;
    const int *inv = f->b_inv.p, *lp = f->b_lp.p, *li = f->b_li.p;
    const double *lx = f->b_lx.p, *dd = f->b_d.p;
    double *y = f->b_y.p;   /* scratch of m: the factorization is done with it */
    for (j = 0; j < m; ++j) y[j] = x[inv[j]];
    for (j = 0; j < m; ++j) {
        double yj = y[j];
        for (p = lp[j]; p < lp[j + 1]; ++p) y[li[p]] -= lx[p] * yj;
    }
    for (j = 0; j < m; ++j) y[j] /= dd[j];
    for (j = m - 1; j >= 0; --j) {
        double s = y[j];
        for (p = lp[j]; p < lp[j + 1]; ++p) s -= lx[p] * y[li[p]];
        y[j] = s;
    }
    for (j = 0; j < m; ++j) x[inv[j]] = y[j];
}

long lc_sparse_ldl_entries(const lc_sparse_ldl *f) { return f->entries; }
