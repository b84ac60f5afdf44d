/* vdag: build, inspect, query and render .vdag files. */
#include <stdio.h>
#include <string.h>
int main(int argc, char **argv) {
    if (argc > 1 && !strcmp(argv[1], "--help")) { puts("usage: vdag COMMAND ..."); return 0; }
    fprintf(stderr, "vdag: usage: vdag COMMAND ...\n");
    return 2;
}
