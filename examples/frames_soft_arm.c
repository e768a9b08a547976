/* frames_soft_arm.c - inverse control of a cable-driven soft arm with the reduced chain model
   of frames.h (Bosman 2015, ch. 5; issue 15). A tapered arm of 16 vertebrae (radius 30 mm
   at the base to 15 mm at the tip, 0.5 m long, silicone-like E = 20 MPa, gravity along -z),
   each intervertebra an equivalent 6-DoF spring (Euler-Bernoulli compliance of its mean
   section), driven like the thesis's CBHA by two sections of three actuators at 120
   degrees: here cables routed through every vertebra of their section (tension 0..300 N).
   Its tip follows, open loop, a circle of 60 mm radius at 2.5 cm/s and a square of 80 mm
   side at 3.1 cm/s in the y-z plane (the thesis's fig. 5.9), one inverse step (linearise,
   factor, W blocks, QP of eq. 5.29, apply) per 20 ms control period. Prints target,
   reached position and efforts every 100 steps, the tracking error and the time per
   control step; writes frames_soft_arm.csv (one row per control step) to plot.

       cc -O2 examples/frames_soft_arm.c -lm && ./a.out [output-directory]

   The inverse controller (inverse simulation by QP in constraint space) is the subject of
   patent FR3002047 / WO2014122134A1 (Inria, priority 8 February 2013): check its status
   before deploying it commercially. Exit status 0, 1 when the model fails or a file or the
   printout cannot be written, 2 for a bad argument. */
#define FRAMES_IMPLEMENTATION
#include "../frames.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define VERTEBRAE 16
#define N (VERTEBRAE + 1) /* frames: the base and 16 vertebrae */
#define PI 3.14159265358979323846

static void usage(void)
{
    fprintf(stderr, "usage: frames_soft_arm [output-directory]\n");
    exit(2);
}

/* Euler-Bernoulli compliance of a link of length l along x (see frm_chain_desc.compliances). */
static void link_compliance(double l, double E, double nu, double r, frm_real C[36])
{
    double A = PI * r * r, I = PI * r * r * r * r / 4, G = E / (2 * (1 + nu));
    int k;
    for (k = 0; k < 36; k++) C[k] = 0;
    C[0] = (frm_real)(l / (E * A));
    C[7] = C[14] = (frm_real)(l * l * l / (3 * E * I));
    C[21] = (frm_real)(l / (G * 2 * I));
    C[28] = C[35] = (frm_real)(l / (E * I));
    C[6 * 1 + 5] = C[6 * 5 + 1] = (frm_real)(l * l / (2 * E * I));
    C[6 * 2 + 4] = C[6 * 4 + 2] = (frm_real)(-l * l / (2 * E * I));
}

/* Point at arc length s (m) along a closed path: circle of radius 60 mm, or square of side 80
   mm, centred on c in the y-z plane. */
static void path_point(int square, double s, const double c[3], frm_real out[3])
{
    out[0] = (frm_real)c[0];
    if (!square) {
        double a = s / 0.06;
        out[1] = (frm_real)(c[1] + 0.06 * cos(a));
        out[2] = (frm_real)(c[2] + 0.06 * sin(a));
    } else {
        double h = 0.04, t = fmod(s, 0.32);
        int side = (int)(t / 0.08);
        double u = t - 0.08 * side - h;
        double y = side == 0 ? h : side == 1 ? -u : side == 2 ? -h : u;
        double z = side == 0 ? u : side == 1 ? h : side == 2 ? -u : -h;
        out[1] = (frm_real)(c[1] + y);
        out[2] = (frm_real)(c[2] + z);
    }
}

int main(int argc, char **argv)
{
    const char *dir = ".";
    char path[512];
    frm_real pos[3 * N], comp[36 * N], mass[N], inertia[N], pts[3 * 2 * N * 3];
    int pframes[2 * N * 3], i, a, np = 0, err, shape;
    frm_actuator act[6];
    frm_chain_desc d = frm_chain_default_desc();
    frm_chain *c = NULL;
    double L = 0.5, E = 2e7, centre[3];
    frm_real tip[3];
    FILE *csv;
    if (argc > 2 || (argc == 2 && argv[1][0] == '-')) usage();
    if (argc == 2) dir = argv[1];
    snprintf(path, sizeof path, "%s/frames_soft_arm.csv", dir);
    csv = fopen(path, "w");
    if (!csv) {
        fprintf(stderr, "frames_soft_arm: cannot write %s\n", path);
        return 1;
    }
    for (i = 0; i < N; i++) {
        double r = 0.03 - 0.015 * i / (N - 1.0), rm = 0.03 - 0.015 * (i + 0.5) / (N - 1.0);
        pos[3 * i] = (frm_real)(L * i / (N - 1)), pos[3 * i + 1] = pos[3 * i + 2] = 0;
        mass[i] = (frm_real)(1100 * PI * r * r * L / (N - 1)); /* silicone, 1100 kg/m^3 */
        inertia[i] = (frm_real)(mass[i] * r * r / 2);
        if (i + 1 < N) link_compliance(L / (N - 1), E, 0.45, rm, comp + 36 * i);
    }
    for (a = 0; a < 6; a++) { /* section 1: vertebrae 0..8, section 2: 0..16, turned by 60 degrees */
        int last = a < 3 ? VERTEBRAE / 2 : VERTEBRAE, k;
        double ang = 2 * PI * (a % 3) / 3 + (a < 3 ? 0 : PI / 3);
        memset(&act[a], 0, sizeof act[a]);
        act[a].kind = FRM_ACTUATOR_CABLE;
        act[a].point_count = last + 1;
        act[a].point_frames = pframes + np;
        act[a].points = pts + 3 * np;
        act[a].min_effort = 0;
        act[a].max_effort = 300;
        for (k = 0; k <= last; k++) {
            double r = 0.8 * (0.03 - 0.015 * k / (N - 1.0));
            pframes[np + k] = k;
            pts[3 * (np + k)] = pos[3 * k];
            pts[3 * (np + k) + 1] = (frm_real)(r * cos(ang));
            pts[3 * (np + k) + 2] = (frm_real)(r * sin(ang));
        }
        np += last + 1;
    }
    d.frame_count = N;
    d.positions = pos;
    d.compliances = comp;
    d.masses = mass;
    d.inertias = inertia;
    d.actuators = act;
    d.actuator_count = 6;
    err = frm_chain_create(&d, &c);
    if (!err) err = frm_chain_solve_static(c); /* sagging under its own weight */
    if (err) {
        fprintf(stderr, "frames_soft_arm: %s\n", frm_error_string(err));
        fclose(csv);
        return 1;
    }
    frm_chain_effector(c, tip, NULL);
    /* the paths' centre: 10 mm behind the sagging tip (bending shortens the arm's reach) */
    centre[0] = (double)tip[0] - 0.01, centre[1] = (double)tip[1], centre[2] = (double)tip[2];
    printf("tapered arm: %d vertebrae, %.2f m, tip at rest (%.4f, %.4f, %.4f) m under gravity\n", VERTEBRAE, L,
           (double)tip[0], (double)tip[1], (double)tip[2]);
    fprintf(csv, "path,step,time_s,target_x,target_y,target_z,tip_x,tip_y,tip_z,error_mm");
    for (a = 0; a < 6; a++) fprintf(csv, ",tension%d_N", a);
    fprintf(csv, ",linearizations,step_us\n");
    for (shape = 0; shape < 2; shape++) {
        double speed = shape ? 0.031 : 0.025, length = shape ? 0.32 : 2 * PI * 0.06, period = 0.02, emax = 0, esum = 0;
        double tsum = 0, tmax = 0;
        int steps = (int)(length / (speed * period)) + 1, s, settle, unreachable = 0;
        frm_real target[3];
        frm_inverse_stats st;
        /* move onto the path's start (a few linearisations, not timed) */
        path_point(shape, 0, centre, target);
        err = frm_chain_inverse_solve(c, target, 1e-4, 20, &st);
        if (err && err != FRM_ERR_UNREACHABLE) break;
        settle = st.linearizations;
        printf("%s: %d control steps of %.0f ms at %.1f cm/s (start reached in %d linearisations)\n",
               shape ? "square 80 mm" : "circle 60 mm", steps, 1e3 * period, 100 * speed, settle);
        for (s = 1; s <= steps; s++) {
            clock_t t0;
            double us;
            path_point(shape, speed * period * s, centre, target);
            t0 = clock();
            err = frm_chain_inverse_step(c, target, 1e-4, &st);
            us = 1e6 * (double)(clock() - t0) / CLOCKS_PER_SEC;
            if (err == FRM_ERR_UNREACHABLE) unreachable++, err = FRM_OK;
            if (err) break;
            frm_chain_effector(c, tip, NULL);
            tsum += us;
            tmax = us > tmax ? us : tmax;
            esum += st.error;
            emax = st.error > emax ? st.error : emax;
            fprintf(csv, "%s,%d,%.3f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.4f", shape ? "square" : "circle", s, period * s,
                    (double)target[0], (double)target[1], (double)target[2], (double)tip[0], (double)tip[1],
                    (double)tip[2], 1e3 * st.error);
            for (a = 0; a < 6; a++) fprintf(csv, ",%.3f", (double)frm_chain_efforts(c)[a]);
            fprintf(csv, ",%d,%.1f\n", st.linearizations, us);
            if (s % 100 == 0)
                printf("  t %5.2f s target (%.4f, %.4f, %.4f) tip (%.4f, %.4f, %.4f) m, tensions %.1f %.1f %.1f | %.1f %.1f %.1f N\n",
                       period * s, (double)target[0], (double)target[1], (double)target[2], (double)tip[0],
                       (double)tip[1], (double)tip[2], (double)frm_chain_efforts(c)[0], (double)frm_chain_efforts(c)[1],
                       (double)frm_chain_efforts(c)[2], (double)frm_chain_efforts(c)[3], (double)frm_chain_efforts(c)[4],
                       (double)frm_chain_efforts(c)[5]);
        }
        if (err) break;
        printf("  tracking error (one linearisation a step): mean %.3f mm, max %.3f mm; %d steps out of reach\n",
               1e3 * esum / steps, 1e3 * emax, unreachable);
        printf("  time per control step: mean %.1f us, max %.1f us (%.0f Hz)\n", tsum / steps, tmax,
               tsum > 0 ? 1e6 * steps / tsum : 0.0);
    }
    frm_chain_destroy(c);
    if (err) {
        fprintf(stderr, "frames_soft_arm: %s\n", frm_error_string(err));
        fclose(csv);
        return 1;
    }
    if (fclose(csv) != 0) {
        fprintf(stderr, "frames_soft_arm: cannot write %s\n", path);
        return 1;
    }
    printf("wrote %s\n", path);
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, "frames_soft_arm: writing the printout failed\n");
        return 1;
    }
    return 0;
}
