/* Finding and starting the preview's node scripts (see node_tool.h). */
#define _POSIX_C_SOURCE 200809L
#include "node_tool.h"

#include <errno.h>
#include <limits.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

int node_tool_path(const char *script, char *out, size_t size)
{
    char root[PATH_MAX];
    const char *env = getenv("LMBAKE_ROOT");
    if (env && env[0]) {
        snprintf(root, sizeof root, "%s", env);
    } else {
        ssize_t n = readlink("/proc/self/exe", root, sizeof root - 1);
        if (n <= 0) {
            fprintf(stderr, "lmbake: error: cannot find the lmbake executable's folder; set LMBAKE_ROOT\n");
            return 0;
        }
        root[n] = '\0';
        for (int up = 0; up < 2; up++) { /* <root>/build/lmbake -> <root> */
            char *slash = strrchr(root, '/');
            if (slash)
                *slash = '\0';
        }
    }
    snprintf(out, size, "%s/tools/preview/%s", root, script);
    if (access(out, R_OK) != 0) {
        fprintf(stderr, "lmbake: error: %s not found (set LMBAKE_ROOT to the lmbake checkout; tools/setup.sh installs node and the npm packages)\n", out);
        return 0;
    }
    return 1;
}

/* argv for node: "node", script, args..., NULL */
static char **node_argv(const char *script, char *const args[])
{
    size_t n = 0;
    while (args[n])
        n++;
    char **argv = calloc(n + 3, sizeof *argv);
    if (!argv)
        return NULL;
    argv[0] = "node";
    argv[1] = (char *)script;
    for (size_t i = 0; i < n; i++)
        argv[i + 2] = args[i];
    return argv;
}

int node_tool_exec(const char *script, char *const args[])
{
    char **argv = node_argv(script, args);
    if (!argv)
        return 3;
    fflush(NULL);
    execvp("node", argv);
    fprintf(stderr, "lmbake: error: cannot start node (%s): run tools/setup.sh\n", strerror(errno));
    free(argv);
    return 3;
}

int node_tool_run(const char *script, char *const args[])
{
    char **argv = node_argv(script, args);
    if (!argv)
        return -1;
    fflush(NULL);
    pid_t pid;
    int rc = posix_spawnp(&pid, "node", NULL, NULL, argv, environ), status = 0;
    free(argv);
    if (rc != 0) {
        fprintf(stderr, "lmbake: error: cannot start node (%s): run tools/setup.sh\n", strerror(rc));
        return -1;
    }
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
        ;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
