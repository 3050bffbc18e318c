/* Strict parsing of option values: the whole string must be a number in
 * range, or the command line is wrong. */
#ifndef ZT_APP_PARSE_H
#define ZT_APP_PARSE_H

int parse_int(const char *option, const char *text, long lo, long hi, int *out);
int parse_u64(const char *option, const char *text, unsigned long long *out);
int parse_double(const char *option, const char *text, double lo, double hi, double *out);
/* "WxH" */
int parse_size(const char *option, const char *text, int *w, int *h);
/* Bytes: "4096", "512M", "8G", "1.5GiB" (K, M, G, T are powers of 1024). */
int parse_bytes(const char *option, const char *text, unsigned long long *out);
/* "0,2,5" */
int parse_int_list(const char *option, const char *text, int *out, int max, int *count);

#endif
