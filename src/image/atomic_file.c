/* Temporary file + fsync + rename, so a crash or a failed write never leaves
 * a truncated image under the target's name.  POSIX only. */
#define _POSIX_C_SOURCE 200809L
#include "image/atomic_file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "util/error.h"

/* open(O_EXCL) rather than mkstemp: mkstemp makes the file 0600, whereas an
 * image should get the usual 0666 & ~umask, and reading the umask is not
 * thread-safe. */
static uint64_t next_random(void)
{
    static atomic_uint_fast64_t counter;
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    uint64_t z = (uint64_t)ts.tv_nsec ^ ((uint64_t)ts.tv_sec << 30) ^
                 ((uint64_t)getpid() << 16) ^
                 (atomic_fetch_add(&counter, 1) * 0x9e3779b97f4a7c15u);
    /* splitmix64 finaliser: spreads the bits over the suffix */
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

static int create_temporary(char *tmp_path, size_t suffix_at)
{
    static const char alphabet[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
    for (int attempt = 0; attempt < 100; attempt++) {
        uint64_t r = next_random();
        for (int i = 0; i < 6; i++, r /= 62)
            tmp_path[suffix_at + (size_t)i] = alphabet[r % 62];
        int fd = open(tmp_path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0 || errno != EEXIST)
            return fd;
    }
    return -1; /* errno is still EEXIST */
}

static void release(atomic_file *file)
{
    free(file->target);
    free(file->tmp_path);
    file->stream = NULL;
    file->target = NULL;
    file->tmp_path = NULL;
}

zt_status atomic_file_open(atomic_file *file, const char *target, zt_error *err)
{
    static const char suffix[] = ".tmp.XXXXXX";
    size_t len = strlen(target);
    file->stream = NULL;
    file->target = malloc(len + 1);
    file->tmp_path = malloc(len + sizeof suffix);
    if (!file->target || !file->tmp_path) {
        release(file);
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", target);
    }
    memcpy(file->target, target, len + 1);
    memcpy(file->tmp_path, target, len);
    memcpy(file->tmp_path + len, suffix, sizeof suffix);

    int fd = create_temporary(file->tmp_path, len + sizeof suffix - 7);
    if (fd < 0) {
        int e = errno;
        release(file);
        return zt_fail(err, ZT_ERR_WRITE, "%s: cannot create a temporary file: %s",
                       target, strerror(e));
    }
    file->stream = fdopen(fd, "wb");
    if (!file->stream) {
        int e = errno;
        close(fd);
        unlink(file->tmp_path);
        zt_fail(err, ZT_ERR_WRITE, "%s: %s", target, strerror(e));
        release(file);
        return ZT_ERR_WRITE;
    }
    return ZT_OK;
}

/* Makes the rename itself durable; best effort, as some file systems
 * refuse fsync on directories. */
static void sync_directory(const char *target)
{
    const char *slash = strrchr(target, '/');
    char *dir = slash ? strndup(target, (size_t)(slash - target) + 1) : strdup(".");
    if (!dir)
        return;
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        (void)fsync(fd);
        close(fd);
    }
    free(dir);
}

zt_status atomic_file_commit(atomic_file *file, zt_error *err)
{
    if (!file->stream)
        return zt_fail(err, ZT_ERR_WRITE, "%s: file already closed",
                       file->target ? file->target : "(null)");
    const char *step = "write";
    int e = 0;
    errno = 0;
    if (fflush(file->stream) != 0 || ferror(file->stream))
        e = errno ? errno : EIO;
    else if (fsync(fileno(file->stream)) != 0)
        step = "fsync", e = errno;
    /* fclose can report the write-back error of a network file system */
    if (fclose(file->stream) != 0 && e == 0)
        step = "close", e = errno;
    file->stream = NULL;
    if (e == 0 && rename(file->tmp_path, file->target) != 0)
        step = "rename", e = errno;
    if (e != 0) {
        unlink(file->tmp_path);
        zt_fail(err, ZT_ERR_WRITE, "%s: %s failed: %s", file->target, step,
                strerror(e));
        release(file);
        return ZT_ERR_WRITE;
    }
    sync_directory(file->target);
    release(file);
    return ZT_OK;
}

void atomic_file_abort(atomic_file *file)
{
    if (file->stream) {
        fclose(file->stream);
        unlink(file->tmp_path);
    }
    release(file);
}
