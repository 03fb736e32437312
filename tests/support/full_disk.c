// full_disk.c - a disk that fills up, for the tests of failed writes (tests/output_files_test.cpp).
//
// Loaded with LD_PRELOAD into one `raster` run: a write() to a regular file under the run's working
// folder that would take the file past SR_FULL_DISK_BYTES writes what fits and then fails with ENOSPC,
// as a full disk answers. Files elsewhere (the captured stdout and stderr, the drivers' caches) and
// everything that is not a regular file are written as usual.
//
// Why not `ulimit -f`: the file-size limit applies to every file the process sizes, memfd files among
// them, and lavapipe from Mesa 25 backs device memory with one (memfd_create, then ftruncate, whose
// EFBIG it does not check): the first allocation past the limit is a SIGBUS in the driver, long
// before any output is written. A full disk does not touch memfd files.
//
// The project's writer (host/io/file_write.cpp) writes through write() alone, so one wrapper covers
// every output; a writer that went around it would write its file whole, and the tests would fail.
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

typedef ssize_t (*WriteFn)(int, const void*, size_t);

// The file behind `fd` lies under the working folder: its path starts with the folder's and a '/'.
static int underWorkingFolder(int fd)
{
    char link[64], path[PATH_MAX], folder[PATH_MAX];
    snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
    const ssize_t n = readlink(link, path, sizeof path - 1);
    if (n <= 0 || getcwd(folder, sizeof folder) == NULL) return 0;
    path[n] = '\0';
    const size_t length = strlen(folder);
    return strncmp(path, folder, length) == 0 && path[length] == '/';
}

ssize_t write(int fd, const void* data, size_t count)
{
    static WriteFn next = NULL;
    if (next == NULL) next = (WriteFn)dlsym(RTLD_NEXT, "write");
    const char* limitText = getenv("SR_FULL_DISK_BYTES");
    struct stat st;
    if (limitText == NULL || count == 0 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) ||
        !underWorkingFolder(fd))
        return next(fd, data, count);
    const off_t limit = (off_t)strtoll(limitText, NULL, 10);
    const off_t at = lseek(fd, 0, SEEK_CUR);
    if (at < 0) return next(fd, data, count);
    if (at >= limit) {
        errno = ENOSPC;
        return -1;
    }
    const size_t room = (size_t)(limit - at);
    return next(fd, data, count < room ? count : room);
}
