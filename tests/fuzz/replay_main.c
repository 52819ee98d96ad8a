/* Replays inputs through a libFuzzer harness without libFuzzer (any C compiler): each argument
 * is a file, or a folder whose regular files are replayed in name order. Deterministic; a broken
 * invariant aborts inside the harness. Prints how many inputs ran. */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int replay_file(const char *path)
{
    FILE *file = fopen(path, "rb");
    uint8_t *data;
    long size;
    if (file == NULL || fseek(file, 0, SEEK_END) != 0 || (size = ftell(file)) < 0 || fseek(file, 0, SEEK_SET) != 0) {
        fprintf(stderr, "replay: cannot read %s\n", path);
        if (file != NULL) {
            fclose(file);
        }
        return -1;
    }
    data = malloc((size_t)size + 1u);
    if (data == NULL || fread(data, 1u, (size_t)size, file) != (size_t)size) {
        fprintf(stderr, "replay: cannot read %s\n", path);
        free(data);
        fclose(file);
        return -1;
    }
    fclose(file);
    LLVMFuzzerTestOneInput(data, (size_t)size);
    free(data);
    return 0;
}

static int by_name(const void *a, const void *b) { return strcmp(*(const char *const *)a, *(const char *const *)b); }

int main(int argc, char **argv)
{
    int i;
    unsigned runs = 0;
    for (i = 1; i < argc; ++i) {
        struct stat info;
        if (stat(argv[i], &info) != 0) {
            fprintf(stderr, "replay: no such file or folder: %s\n", argv[i]);
            return 1;
        }
        if (S_ISDIR(info.st_mode)) {
            DIR *dir = opendir(argv[i]);
            struct dirent *entry;
            char **names = NULL;
            size_t count = 0, n;
            if (dir == NULL) {
                fprintf(stderr, "replay: cannot open %s\n", argv[i]);
                return 1;
            }
            while ((entry = readdir(dir)) != NULL) {
                char **grown;
                if (entry->d_name[0] == '.') {
                    continue;
                }
                grown = realloc(names, (count + 1u) * sizeof *names);
                if (grown == NULL) {
                    return 1;
                }
                names = grown;
                names[count] = malloc(strlen(argv[i]) + strlen(entry->d_name) + 2u);
                if (names[count] == NULL) {
                    return 1;
                }
                sprintf(names[count], "%s/%s", argv[i], entry->d_name);
                ++count;
            }
            closedir(dir);
            qsort(names, count, sizeof *names, by_name);
            for (n = 0; n < count; ++n) {
                if (replay_file(names[n]) != 0) {
                    return 1;
                }
                ++runs;
                free(names[n]);
            }
            free(names);
        } else {
            if (replay_file(argv[i]) != 0) {
                return 1;
            }
            ++runs;
        }
    }
    if (runs == 0u) {
        fprintf(stderr, "replay: no input\n");
        return 1;
    }
    printf("replay: %u inputs, every invariant held\n", runs);
    return 0;
}
