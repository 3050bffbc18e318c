/* zonetrace compare: error figures of an image against a reference, one
 * "name value" pair per line for scripts. */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "parse.h"

static void compare_usage(FILE *f)
{
    fprintf(f,
"usage: zonetrace compare IMAGE REFERENCE [--block N] [--noise VARIANCE]\n"
"\n"
"Prints, one per line: rel_rmse (sqrt(mean((a-b)^2)) / mean(b) over all pixels\n"
"and channels), rmse, psnr (dB, against the reference's maximum) and the\n"
"per-channel means of both images.  --block N first averages both images over\n"
"NxN pixel blocks.  --noise VARIANCE (the reference's variance of the mean per\n"
"pixel and channel, as bench_reference --noise writes it) adds rel_rmse_own:\n"
"rel_rmse with the reference's own noise taken out.  The images must have the\n"
"same size.\n");
}

int cli_compare(int argc, char **argv)
{
    static const struct option opts[] = {
        {"block", required_argument, 0, 'b'}, {"noise", required_argument, 0, 'n'},
        {"help", no_argument, 0, 'h'},        {0, 0, 0, 0}};
    int block = 1, c;
    const char *noise = NULL;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, ":h", opts, NULL)) != -1) {
        if (c == 'b') {
            if (!parse_int("--block", optarg, 1, 4096, &block))
                return EXIT_USAGE;
        } else if (c == 'n') {
            noise = optarg;
        } else if (c == 'h') {
            compare_usage(stdout);
            return EXIT_OK;
        } else {
            cli_error("unknown option or missing value: '%s'", argv[optind - 1]);
            return EXIT_USAGE;
        }
    }
    if (argc - optind != 2) {
        cli_error("compare needs exactly two images");
        compare_usage(stderr);
        return EXIT_USAGE;
    }
    zt_error err;
    zt_error_clear(&err);
    zt_image *img[3] = {NULL, NULL, NULL};
    const char *path[3] = {argv[optind], argv[optind + 1], noise};
    int count = noise ? 3 : 2, code = EXIT_OK;
    for (int i = 0; i < count && code == EXIT_OK; i++) {
        zt_status st = zt_image_read(path[i], &img[i], &err);
        if (st != ZT_OK) {
            cli_error("%s", err.message);
            code = cli_exit_code(st);
        }
    }
    if (code == EXIT_OK && block > 1) {
        for (int i = 0; i < count; i++) {
            zt_image *small = zt_image_downsample(img[i], block);
            if (!small) {
                cli_error("--block %d does not divide the size of '%s' (%dx%d)", block,
                          path[i], img[i]->width, img[i]->height);
                code = EXIT_USAGE;
                break;
            }
            zt_image_release(img[i]);
            img[i] = small;
        }
    }
    if (code == EXIT_OK) {
        zt_compare_result r;
        zt_status st = zt_image_compare(img[0], img[1], &r, &err);
        if (st != ZT_OK) {
            cli_error("%s", err.message);
            code = cli_exit_code(st);
        } else {
            printf("rel_rmse %.6g\nrmse %.6g\npsnr %.4f\n", r.rel_rmse, r.rmse, r.psnr);
            printf("mean_image %.6g %.6g %.6g\n", r.mean_a[0], r.mean_a[1], r.mean_a[2]);
            printf("mean_reference %.6g %.6g %.6g\n", r.mean_b[0], r.mean_b[1], r.mean_b[2]);
        }
    }
    if (code == EXIT_OK && noise) {
        /* A block's mean has 1/block^2 of its pixels' mean variance. */
        double own;
        zt_status st = zt_image_own_error(img[0], img[1], img[2], 1.0 / ((double)block * block),
                                          &own, &err);
        if (st != ZT_OK) {
            cli_error("%s", err.message);
            code = cli_exit_code(st);
        } else {
            printf("rel_rmse_own %.6g\n", own);
        }
    }
    for (int i = 0; i < 3; i++)
        zt_image_release(img[i]);
    return code;
}
