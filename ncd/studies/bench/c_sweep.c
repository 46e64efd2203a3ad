/* The NLGS sweep of ncd (ncd/solver/kernels.py: sweep_discs;
 * ncd/solver/single_contact.py: solve_single_contact, the general formulas, which the
 * sweep's solve_disc_contact must match bit for bit) in plain C, on the same packed
 * arrays, as the hardware reference of ncd/studies/bench/solver.py (nlgs_sweep_cost).
 * Input: a raw file written by ncd.studies.bench.solver
 *   int64 n, n_body, sweeps; int64 order[n]; int32 pair[n][2];
 *   double coef[n][13]; double body[n_body][4]; double imp[n][2]
 * The Delassus blocks of disc contacts are diagonal (W_nt = W_tn = 0).
 * Output: seconds per sweep (best of 3 runs of `sweeps` sweeps) on stdout, and the
 * final impulses (double[n][2]) in the file given as second argument.
 * Build: gcc -O3 -ffp-contract=off -o c_sweep c_sweep.c (no fused
 * multiply-adds, so that the operations and their roundings are numba's).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { NX, NY, RA, RB, WNN, WTT, MU, BN, BT, IMA, IIA, IMB, IIB, NCOEF = 13 };

static void project_cone(double zn, double zt, double mu, double *pn, double *pt) {
    double at = fabs(zt);
    if (zn >= 0.0 && at <= mu * zn) { *pn = zn; *pt = zt; return; }
    if (mu * at <= -zn) { *pn = 0.0; *pt = 0.0; return; }
    *pn = (zn + mu * at) / (1.0 + mu * mu);
    *pt = zt > 0.0 ? mu * *pn : -mu * *pn;
}

static int solve(double wnn, double wnt, double wtn, double wtt, double qn, double qt, double mu,
                 double *rn, double *rt) {
    if (qn >= 0.0) { *rn = 0.0; *rt = 0.0; return 0; }
    double det = wnn * wtt - wnt * wtn;
    double sn = (-wtt * qn + wnt * qt) / det, st = (wtn * qn - wnn * qt) / det;
    if (sn >= 0.0 && fabs(st) <= mu * sn) { *rn = sn; *rt = st; return 1; }
    for (int k = 0; k < 2; k++) {
        double sigma = k == 0 ? 1.0 : -1.0, denom = wnn - sigma * mu * wnt;
        if (denom > 0.0) {
            double n_ = -qn / denom, t_ = -sigma * mu * n_, ut = wtn * n_ + wtt * t_ + qt;
            if (sigma * ut >= 0.0) { *rn = n_; *rt = t_; return 2 + k; }
        }
    }
    project_cone(sn, st, mu, rn, rt);
    return 4;
}

static void sweep(int64_t n, const int64_t *order, const int32_t *pair, const double *coef,
                  double *body, double *imp, int8_t *status, double *dsum_, double *ssum_) {
    double dsum = 0.0, ssum = 0.0;
    for (int64_t k = 0; k < n; k++) {
        int64_t c = order[k], a = pair[2 * c], b = pair[2 * c + 1];
        const double *p = coef + NCOEF * c;
        double *ba = body + 4 * a, *bb = body + 4 * b;
        double vx = ba[0] - bb[0], vy = ba[1] - bb[1], wt = p[RA] * ba[2] + p[RB] * bb[2];
        double un = vx * p[NX] + vy * p[NY], ut = -vx * p[NY] + vy * p[NX] - wt;
        double sn = imp[2 * c], st = imp[2 * c + 1];
        double qn = un - p[WNN] * sn + p[BN];
        double qt = ut - p[WTT] * st + p[BT];
        double rn, rt;
        status[c] = (int8_t)solve(p[WNN], 0.0, 0.0, p[WTT], qn, qt, p[MU], &rn, &rt);
        double dn = rn - sn, dt = rt - st;
        imp[2 * c] = rn; imp[2 * c + 1] = rt;
        double px = dn * p[NX] - dt * p[NY], py = dn * p[NY] + dt * p[NX];
        ba[0] += p[IMA] * px; ba[1] += p[IMA] * py; ba[2] -= p[IIA] * dt;
        bb[0] -= p[IMB] * px; bb[1] -= p[IMB] * py; bb[2] -= p[IIB] * dt;
        dsum += fabs(dn) + fabs(dt);
        ssum += fabs(rn) + fabs(rt);
    }
    *dsum_ = dsum; *ssum_ = ssum;
}

static void *load(FILE *f, size_t bytes) {
    void *p = malloc(bytes);
    if (!p || fread(p, 1, bytes, f) != bytes) { fprintf(stderr, "short input\n"); exit(1); }
    return p;
}

int main(int argc, char **argv) {
    if (argc != 3) { fprintf(stderr, "usage: c_sweep problem.bin impulses.bin\n"); return 2; }
    FILE *f = fopen(argv[1], "rb");
    if (!f) { perror(argv[1]); return 1; }
    int64_t hdr[3];
    if (fread(hdr, sizeof hdr, 1, f) != 1) { fprintf(stderr, "short input\n"); return 1; }
    int64_t n = hdr[0], nb = hdr[1], sweeps = hdr[2];
    int64_t *order = load(f, 8 * n);
    int32_t *pair = load(f, 8 * n);
    double *coef = load(f, 8 * NCOEF * n), *body0 = load(f, 32 * nb), *imp0 = load(f, 16 * n);
    fclose(f);
    double *body = malloc(32 * nb), *imp = malloc(16 * n), best = 1e300, dsum = 0, ssum = 0;
    int8_t *status = malloc(n);
    for (int rep = 0; rep < 3; rep++) {
        memcpy(body, body0, 32 * nb);
        memcpy(imp, imp0, 16 * n);
        struct timespec t0, t1;
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t0);
        for (int64_t s = 0; s < sweeps; s++) sweep(n, order, pair, coef, body, imp, status, &dsum, &ssum);
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t1);
        double dt = (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec);
        if (dt < best) best = dt;
    }
    FILE *g = fopen(argv[2], "wb");
    if (!g || fwrite(imp, 16, n, g) != (size_t)n) { perror(argv[2]); return 1; }
    fclose(g);
    printf("%.9e\n", best / sweeps);
    return 0;
}
