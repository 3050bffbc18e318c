/* The image readers (PNG, PPM, PFM, OpenEXR: chosen by the file's first
 * bytes, as `zonetrace compare` reads them) on arbitrary files. */
#include <stdlib.h>

#include "fuzz.h"
#include "zonetrace/image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_scratch_file(data, size, ".img");
    zt_image *img = NULL;
    zt_error err;
    zt_error_clear(&err);
    if (zt_image_read(path, &img, &err) == ZT_OK) {
        zt_compare_result r;
        zt_image_compare(img, img, &r, &err);
        zt_image_release(img);
    } else if (!err.message[0]) {
        abort();
    }
    return 0;
}
