/* OpenEXR through its C API (OpenEXRCore).  We write one scanline part with
 * FLOAT R, G, B channels (full precision: renders are compared against
 * references, so HALF's 11 bits would add error) and ZIP compression, top
 * row first.  We read the first part of a scanline file with HALF or FLOAT
 * R, G, B channels (or a lone Y channel, taken as grey); tiled and deep
 * files are refused as unsupported.
 * All I/O goes through our own callbacks on the caller's file descriptor,
 * so writing lands in the atomic temporary, and the library's error
 * messages are captured instead of printed. */
#define _POSIX_C_SOURCE 200809L
#include "image/image_io.h"

#include <errno.h>
#include <openexr.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "util/error.h"

typedef struct exr_io {
    int fd;
    char message[200]; /* the library's first complaint, if any */
} exr_io;

static void on_error(exr_const_context_t ctxt, exr_result_t code, const char *message)
{
    (void)code;
    void *user = NULL;
    if (exr_get_user_data(ctxt, &user) != EXR_ERR_SUCCESS || !user)
        return;
    exr_io *io = user;
    if (!io->message[0])
        snprintf(io->message, sizeof io->message, "%s", message);
}

static int64_t read_at(exr_const_context_t ctxt, void *user, void *buffer, uint64_t size,
                       uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    exr_io *io = user;
    uint64_t done = 0;
    if (offset > (uint64_t)INT64_MAX - size)
        return -1;
    while (done < size) {
        ssize_t n = pread(io->fd, (char *)buffer + done, size - done, (off_t)(offset + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0) {
            error_cb(ctxt, EXR_ERR_READ_IO, "%s", strerror(errno));
            return -1;
        }
        if (n == 0)
            break; /* end of file: the library sees the short count */
        done += (uint64_t)n;
    }
    return (int64_t)done;
}

static int64_t size_of(exr_const_context_t ctxt, void *user)
{
    (void)ctxt;
    struct stat st;
    return fstat(((exr_io *)user)->fd, &st) == 0 ? (int64_t)st.st_size : -1;
}

static int64_t write_at(exr_const_context_t ctxt, void *user, const void *buffer,
                        uint64_t size, uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    exr_io *io = user;
    uint64_t done = 0;
    if (offset > (uint64_t)INT64_MAX - size)
        return -1;
    while (done < size) {
        ssize_t n = pwrite(io->fd, (const char *)buffer + done, size - done,
                           (off_t)(offset + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            error_cb(ctxt, EXR_ERR_WRITE_IO, "%s", n < 0 ? strerror(errno) : "short write");
            return -1;
        }
        done += (uint64_t)n;
    }
    return (int64_t)done;
}

static zt_status exr_failure(zt_error *err, zt_status status, const char *name,
                             const exr_io *io, exr_result_t rv)
{
    return zt_fail(err, status, "%s: %s%s", name, status == ZT_ERR_PARSE ? "bad EXR: " : "",
                   io->message[0] ? io->message : exr_get_error_code_as_string(rv));
}

/* Index of an R, G or B channel in our pixels, or -1. */
static int rgb_index(const char *channel)
{
    return strcmp(channel, "R") == 0 ? 0 : strcmp(channel, "G") == 0 ? 1
         : strcmp(channel, "B") == 0 ? 2 : -1;
}

static exr_result_t write_chunks(exr_context_t ctxt, int part, const zt_image *image)
{
    int32_t lines = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(ctxt, part, &lines);
    if (rv == EXR_ERR_SUCCESS && lines < 1)
        rv = EXR_ERR_INVALID_ARGUMENT;
    exr_encode_pipeline_t encoder = EXR_ENCODE_PIPELINE_INITIALIZER;
    int started = 0;
    size_t row_floats = (size_t)image->width * 3;
    for (int y = 0; rv == EXR_ERR_SUCCESS && y < image->height; y += lines) {
        exr_chunk_info_t chunk;
        rv = exr_write_scanline_chunk_info(ctxt, part, y, &chunk);
        if (rv != EXR_ERR_SUCCESS)
            break;
        rv = started ? exr_encoding_update(ctxt, part, &chunk, &encoder)
                     : exr_encoding_initialize(ctxt, part, &chunk, &encoder);
        if (rv != EXR_ERR_SUCCESS)
            break;
        started = 1;
        for (int c = 0; c < encoder.channel_count; c++) {
            exr_coding_channel_info_t *ch = &encoder.channels[c];
            int index = rgb_index(ch->channel_name);
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = 4;
            ch->user_pixel_stride = 12;
            ch->user_line_stride = (int32_t)(row_floats * 4);
            ch->encode_from_ptr =
                (const uint8_t *)(image->pixels + (size_t)y * row_floats + (size_t)index);
        }
        rv = exr_encoding_choose_default_routines(ctxt, part, &encoder);
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_encoding_run(ctxt, part, &encoder);
    }
    if (started)
        exr_encoding_destroy(ctxt, &encoder);
    return rv;
}

zt_status exr_write_image(FILE *stream, const zt_image *image, const char *name,
                          zt_error *err)
{
    exr_io io = {.fd = fileno(stream)};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_error;
    init.user_data = &io;
    init.write_fn = write_at;
    exr_context_t ctxt = NULL;
    int part = 0;
    exr_result_t rv = exr_start_write(&ctxt, name, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_add_part(ctxt, NULL, EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ctxt, part, image->width, image->height,
                                                 EXR_COMPRESSION_ZIP);
    static const char *const names[3] = {"B", "G", "R"};
    for (int c = 0; c < 3 && rv == EXR_ERR_SUCCESS; c++)
        rv = exr_add_channel(ctxt, part, names[c], EXR_PIXEL_FLOAT,
                             EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_write_header(ctxt);
    if (rv == EXR_ERR_SUCCESS)
        rv = write_chunks(ctxt, part, image);
    /* exr_finish writes the chunk offset table, so its result matters */
    exr_result_t finish = ctxt ? exr_finish(&ctxt) : EXR_ERR_SUCCESS;
    if (rv == EXR_ERR_SUCCESS)
        rv = finish;
    if (rv != EXR_ERR_SUCCESS)
        return exr_failure(err, rv == EXR_ERR_OUT_OF_MEMORY ? ZT_ERR_MEMORY : ZT_ERR_WRITE,
                           name, &io, rv);
    return ZT_OK;
}

/* Which of the file's channels feed our R, G and B. */
typedef struct channel_plan {
    int grey;            /* only Y: decode into R, then copy to G and B */
    const char *use[3];  /* the file's channel names; NULL: none */
} channel_plan;

static zt_status plan_channels(const exr_attr_chlist_t *list, channel_plan *plan,
                               const char *name, zt_error *err)
{
    const exr_attr_chlist_entry_t *found[3] = {NULL, NULL, NULL}, *y = NULL;
    for (int i = 0; i < list->num_channels; i++) {
        const exr_attr_chlist_entry_t *e = &list->entries[i];
        int index = rgb_index(e->name.str);
        if (index >= 0)
            found[index] = e;
        else if (strcmp(e->name.str, "Y") == 0)
            y = e;
    }
    plan->grey = !(found[0] && found[1] && found[2]);
    if (plan->grey) {
        if (!y)
            return zt_fail(err, ZT_ERR_UNSUPPORTED,
                           "%s: EXR has neither R, G, B nor Y channels", name);
        found[0] = y;
        found[1] = found[2] = NULL;
    }
    for (int c = 0; c < 3; c++) {
        plan->use[c] = found[c] ? found[c]->name.str : NULL;
        if (!found[c])
            continue;
        if (found[c]->pixel_type != EXR_PIXEL_HALF && found[c]->pixel_type != EXR_PIXEL_FLOAT)
            return zt_fail(err, ZT_ERR_UNSUPPORTED,
                           "%s: EXR channel %s is not HALF or FLOAT", name,
                           found[c]->name.str);
        if (found[c]->x_sampling != 1 || found[c]->y_sampling != 1)
            return zt_fail(err, ZT_ERR_UNSUPPORTED, "%s: EXR channel %s is subsampled",
                           name, found[c]->name.str);
    }
    return ZT_OK;
}

static int planned_index(const channel_plan *plan, const char *channel)
{
    for (int c = 0; c < 3; c++)
        if (plan->use[c] && strcmp(plan->use[c], channel) == 0)
            return c;
    return -1;
}

static exr_result_t read_chunks(exr_context_t ctxt, const exr_attr_box2i_t *window,
                                const channel_plan *plan, zt_image *image)
{
    int32_t lines = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(ctxt, 0, &lines);
    if (rv == EXR_ERR_SUCCESS && lines < 1)
        rv = EXR_ERR_CORRUPT_CHUNK;
    exr_decode_pipeline_t decoder = EXR_DECODE_PIPELINE_INITIALIZER;
    int started = 0;
    size_t row_floats = (size_t)image->width * 3;
    for (int64_t y = window->min.y; rv == EXR_ERR_SUCCESS && y <= window->max.y; y += lines) {
        exr_chunk_info_t chunk;
        rv = exr_read_scanline_chunk_info(ctxt, 0, (int)y, &chunk);
        if (rv != EXR_ERR_SUCCESS)
            break;
        /* never trust a chunk to stay inside our buffer */
        if (chunk.start_y < window->min.y || chunk.height < 1 ||
            (int64_t)chunk.start_y + chunk.height - 1 > window->max.y ||
            chunk.width != image->width) {
            rv = EXR_ERR_CORRUPT_CHUNK;
            break;
        }
        rv = started ? exr_decoding_update(ctxt, 0, &chunk, &decoder)
                     : exr_decoding_initialize(ctxt, 0, &chunk, &decoder);
        if (rv != EXR_ERR_SUCCESS)
            break;
        started = 1;
        size_t first_row = (size_t)((int64_t)chunk.start_y - window->min.y);
        for (int c = 0; c < decoder.channel_count; c++) {
            exr_coding_channel_info_t *ch = &decoder.channels[c];
            int index = planned_index(plan, ch->channel_name);
            if (index < 0 || ch->height != chunk.height || ch->width != chunk.width) {
                ch->decode_to_ptr = NULL; /* skipped */
                continue;
            }
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = 4;
            ch->user_pixel_stride = 12;
            ch->user_line_stride = (int32_t)(row_floats * 4);
            ch->decode_to_ptr =
                (uint8_t *)(image->pixels + first_row * row_floats + (size_t)index);
        }
        rv = exr_decoding_choose_default_routines(ctxt, 0, &decoder);
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_decoding_run(ctxt, 0, &decoder);
    }
    if (started)
        exr_decoding_destroy(ctxt, &decoder);
    return rv;
}

static zt_status read_part(exr_context_t ctxt, exr_io *io, const char *name,
                           zt_image **out, zt_error *err)
{
    exr_storage_t storage;
    exr_attr_box2i_t window;
    const exr_attr_chlist_t *channels = NULL;
    exr_result_t rv = exr_get_storage(ctxt, 0, &storage);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_data_window(ctxt, 0, &window);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_channels(ctxt, 0, &channels);
    if (rv != EXR_ERR_SUCCESS || !channels)
        return exr_failure(err, ZT_ERR_PARSE, name, io, rv);
    if (storage != EXR_STORAGE_SCANLINE)
        return zt_fail(err, ZT_ERR_UNSUPPORTED,
                       "%s: only scanline EXR images are supported (not tiled or deep)",
                       name);
    int64_t width = (int64_t)window.max.x - window.min.x + 1;
    int64_t height = (int64_t)window.max.y - window.min.y + 1;
    if (!image_size_ok((long)(width > 0 ? width : 0), (long)(height > 0 ? height : 0)))
        return zt_fail(err, ZT_ERR_PARSE, "%s: EXR data window is empty or too large", name);
    channel_plan plan;
    zt_status st = plan_channels(channels, &plan, name, err);
    if (st != ZT_OK)
        return st;

    zt_image *image = zt_image_create((int)width, (int)height);
    if (!image)
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", name);
    rv = read_chunks(ctxt, &window, &plan, image);
    if (rv != EXR_ERR_SUCCESS) {
        zt_image_release(image);
        return exr_failure(err, rv == EXR_ERR_OUT_OF_MEMORY ? ZT_ERR_MEMORY : ZT_ERR_PARSE,
                           name, io, rv);
    }
    if (plan.grey) {
        for (size_t i = 0; i < (size_t)width * (size_t)height; i++)
            image->pixels[3 * i + 1] = image->pixels[3 * i + 2] = image->pixels[3 * i];
    }
    *out = image;
    return ZT_OK;
}

zt_status exr_read_image(FILE *stream, const char *name, zt_image **out, zt_error *err)
{
    exr_io io = {.fd = fileno(stream)};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_error;
    init.user_data = &io;
    init.read_fn = read_at;
    init.size_fn = size_of;
    init.max_image_width = ZT_IMAGE_MAX_SIDE;
    init.max_image_height = ZT_IMAGE_MAX_SIDE;
    *out = NULL;
    exr_context_t ctxt = NULL;
    exr_result_t rv = exr_start_read(&ctxt, name, &init);
    if (rv != EXR_ERR_SUCCESS) {
        if (ctxt)
            exr_finish(&ctxt);
        return exr_failure(err, rv == EXR_ERR_OUT_OF_MEMORY ? ZT_ERR_MEMORY
                                : rv == EXR_ERR_READ_IO ? ZT_ERR_READ : ZT_ERR_PARSE,
                           name, &io, rv);
    }
    zt_status st = read_part(ctxt, &io, name, out, err);
    exr_finish(&ctxt);
    return st;
}
