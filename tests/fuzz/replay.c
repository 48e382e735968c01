/*
** Runs a libFuzzer harness over files without libFuzzer (any compiler): each argument is a file
** or a folder of files, fed to LLVMFuzzerTestOneInput once. `make test` replays the seed corpora
** and every input a fuzzer ever crashed on (tests/fuzz/regressions/NAME/), under the sanitizers
** in `make sanitize`; a crash there fails the suite.
*/
#include <dirent.h>
#include <string.h>
#include <sys/stat.h>

#include "fuzz.h"

static int replay_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "replay: cannot open %s\n", path);
        return 1;
    }
    size_t cap = 1 << 16, n = 0;
    unsigned char *buf = malloc(cap);
    size_t got;
    while (buf && (got = fread(buf + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            unsigned char *b = realloc(buf, 2 * cap);
            if (!b)
                break;
            buf = b;
            cap *= 2;
        }
    }
    fclose(f);
    if (!buf)
        return 1;
    LLVMFuzzerTestOneInput(buf, n);
    free(buf);
    return 0;
}

int main(int argc, char **argv)
{
    int bad = 0, count = 0;
    for (int i = 1; i < argc; i++) {
        struct stat s;
        if (stat(argv[i], &s) != 0)
            continue; /* a folder that does not exist (no regressions yet) */
        if (!S_ISDIR(s.st_mode)) {
            bad |= replay_file(argv[i]);
            count++;
            continue;
        }
        DIR *d = opendir(argv[i]);
        struct dirent *e;
        while (d && (e = readdir(d)) != NULL) {
            char p[4096];
            snprintf(p, sizeof p, "%s/%s", argv[i], e->d_name);
            if (e->d_name[0] != '.' && stat(p, &s) == 0 && S_ISREG(s.st_mode)) {
                bad |= replay_file(p);
                count++;
            }
        }
        if (d)
            closedir(d);
    }
    printf("%s: %d inputs replayed\n", argv[0], count);
    return bad;
}
