/* The fuzz harnesses' shared pieces.  Each harness defines
 * LLVMFuzzerTestOneInput; built with clang -fsanitize=fuzzer it is a
 * libFuzzer program, built with replay_main.c (any compiler) it runs the
 * files named on its command line once each: the regression inputs and
 * the seed corpora run that way in every test build. */
#ifndef ZT_FUZZ_FUZZ_H
#define ZT_FUZZ_FUZZ_H

#include <stddef.h>
#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Writes data to this process's scratch file and returns its path (for
 * readers that take a file name).  Aborts when it cannot: a harness that
 * cannot write its input tests nothing. */
const char *fuzz_scratch_file(const uint8_t *data, size_t size, const char *suffix);

/* fuzz/forest_scene.json, loaded once (aborts when it does not load). */
struct zt_scene;
struct zt_scene *fuzz_small_scene(void);

#endif
