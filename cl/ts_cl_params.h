/*
 * Layout of the per-azimuth parameter tables of the horizon kernels, shared
 * by the host code (cl/cl_horizon.c) and the kernels (this file is the first
 * piece of the embedded kernel source). Integers go to an int table, reals
 * (double on devices with cl_khr_fp64, else float) to a real table, one row
 * of TS_CLI_N / TS_CLD_N entries per azimuth. TS_NEAR_* come from
 * core/cellmath/cm_near_field.h (embedded before this file).
 */
#ifndef TS_CL_PARAMS_H
#define TS_CL_PARAMS_H

/* int table */
#define TS_CLI_XMAJOR 0   /* 1: u = x (column), v = y (row) */
#define TS_CLI_U 1        /* extent along u */
#define TS_CLI_V 2        /* extent along v */
#define TS_CLI_USTART 3
#define TS_CLI_USTEP 4
#define TS_CLI_BLO 5      /* first line's intercept */
#define TS_CLI_LINE0 6    /* work-item index of the azimuth's first line */
#define TS_CLI_FLOFF 7    /* offset of the azimuth's fl / fr tables */
#define TS_CLI_SROFF 8    /* offset of its metres-per-step table, -1: constant */
#define TS_CLI_PLANE 9    /* output plane in the batch */
#define TS_CLI_NPIECES 10 /* near field: exact pieces */
#define TS_CLI_PDU 11     /* near field: piece corner offsets along u */
#define TS_CLI_PDV (TS_CLI_PDU + TS_NEAR_MAX_PIECES)
#define TS_CLI_N (TS_CLI_PDV + TS_NEAR_MAX_PIECES)

/* real table */
#define TS_CLD_T 0        /* v advance per step */
#define TS_CLD_STEPM 1    /* metres per step (constant cell size) */
#define TS_CLD_NEARSKIP 2 /* hull points closer than this are near field */
#define TS_CLD_PSA 3      /* near field pieces: start and end, in steps */
#define TS_CLD_PSB (TS_CLD_PSA + TS_NEAR_MAX_PIECES)
#define TS_CLD_N (TS_CLD_PSB + TS_NEAR_MAX_PIECES)

#endif
