/* Scratch files for harnesses whose readers take a path, and the small
 * scene the forest and checkpoint harnesses render. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "fuzz.h"
#include "zonetrace/scene.h"

#ifndef ZT_SOURCE_DIR
#error "ZT_SOURCE_DIR must name the source tree"
#endif

static char scratch[256];

static void remove_scratch(void)
{
    if (scratch[0])
        unlink(scratch);
}

const char *fuzz_scratch_file(const uint8_t *data, size_t size, const char *suffix)
{
    if (!scratch[0]) {
        const char *dir = getenv("TMPDIR");
        snprintf(scratch, sizeof scratch, "%s/zt_fuzz_%ld%s", dir ? dir : "/tmp",
                 (long)getpid(), suffix);
        atexit(remove_scratch);
    }
    FILE *f = fopen(scratch, "wb");
    if (!f || (size && fwrite(data, 1, size, f) != size) || fclose(f) != 0) {
        perror(scratch);
        abort();
    }
    return scratch;
}

zt_scene *fuzz_small_scene(void)
{
    static zt_scene *scene;
    if (!scene) {
        zt_error err;
        if (zt_scene_load_file(ZT_SOURCE_DIR "/fuzz/forest_scene.json", &scene, &err) != ZT_OK)
            abort();
    }
    return scene;
}
