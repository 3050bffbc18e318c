#include "parse.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

int parse_int(const char *option, const char *text, long lo, long hi, int *out)
{
    char *end;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (errno || end == text || *end || v < lo || v > hi) {
        cli_error("%s expects a whole number from %ld to %ld, not '%s'", option, lo, hi, text);
        return 0;
    }
    *out = (int)v;
    return 1;
}

int parse_u64(const char *option, const char *text, unsigned long long *out)
{
    char *end;
    errno = 0;
    if (text[0] == '-') {
        cli_error("%s expects a non-negative whole number, not '%s'", option, text);
        return 0;
    }
    unsigned long long v = strtoull(text, &end, 10);
    if (errno || end == text || *end) {
        cli_error("%s expects a non-negative whole number, not '%s'", option, text);
        return 0;
    }
    *out = v;
    return 1;
}

int parse_double(const char *option, const char *text, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    if (errno || end == text || *end || !isfinite(v) || v < lo || v > hi) {
        cli_error("%s expects a number from %g to %g, not '%s'", option, lo, hi, text);
        return 0;
    }
    *out = v;
    return 1;
}

int parse_size(const char *option, const char *text, int *w, int *h)
{
    char *end;
    errno = 0;
    long a = strtol(text, &end, 10);
    if (errno || end == text || (*end != 'x' && *end != 'X'))
        goto bad;
    const char *rest = end + 1;
    long b = strtol(rest, &end, 10);
    if (errno || end == rest || *end || a < 1 || b < 1)
        goto bad;
    if (a > 32768 || b > 32768) {
        /* Say what it would take: the float image and the path tracer's
         * sums alone are 36 bytes a pixel. */
        double gib = 36.0 * (double)a * (double)b / (1024.0 * 1024 * 1024);
        cli_error("%s %s: at most 32768 pixels a side (an image of %ldx%ld would need "
                  "about %.0f GiB of memory)", option, text, a, b, gib);
        return 0;
    }
    *w = (int)a;
    *h = (int)b;
    return 1;
bad:
    cli_error("%s expects WIDTHxHEIGHT with each side 1..32768, e.g. 512x512, not '%s'",
              option, text);
    return 0;
}

int parse_int_list(const char *option, const char *text, int *out, int max, int *count)
{
    *count = 0;
    const char *p = text;
    while (*p) {
        char *end;
        errno = 0;
        long v = strtol(p, &end, 10);
        if (errno || end == p || v < 0 || v > 1000000 || (*end && *end != ',')) {
            cli_error("%s expects a comma-separated list of light indices, e.g. 0,2, not '%s'",
                      option, text);
            return 0;
        }
        if (*count >= max) {
            cli_error("%s: at most %d lights can be listed", option, max);
            return 0;
        }
        out[(*count)++] = (int)v;
        p = *end ? end + 1 : end;
    }
    if (*count == 0) {
        cli_error("%s expects at least one light index", option);
        return 0;
    }
    return 1;
}

int parse_bytes(const char *option, const char *text, unsigned long long *out)
{
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    double scale = 1;
    switch (*end) {
    case 'k': case 'K': scale = 1024.0; end++; break;
    case 'm': case 'M': scale = 1024.0 * 1024; end++; break;
    case 'g': case 'G': scale = 1024.0 * 1024 * 1024; end++; break;
    case 't': case 'T': scale = 1024.0 * 1024 * 1024 * 1024; end++; break;
    default: break;
    }
    if (scale > 1 && (*end == 'i' || *end == 'I'))
        end++;
    if (*end == 'b' || *end == 'B')
        end++;
    if (errno || end == text || *end || !(v > 0) || v * scale > 1.8e19) {
        cli_error("%s expects a size such as 512M, 8G or 1.5GiB, not '%s'", option, text);
        return 0;
    }
    *out = (unsigned long long)(v * scale);
    return 1;
}
