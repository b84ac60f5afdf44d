/* vdag rays / vdag render (ray casting of a .vdag file). */
#include "cli.h"

int vdag_cmd_rays(int argc, char **argv) {
    (void)argc;
    (void)argv;
    return vdag_fail("rays: not available yet");
}

int vdag_cmd_render(int argc, char **argv) {
    (void)argc;
    (void)argv;
    return vdag_fail("render: not available yet");
}
