/*
 * `lmbake preview OUT.gltf [--port N] [--lightmap ktx2|hdr]`: serves a baked level to a browser on 127.0.0.1 (the
 * three.js page of tools/preview; docs/preview.md). The server is node's: this command
 * checks its arguments and hands over to tools/preview/serve.mjs.
 */
#include "cli_common.h"
#include "commands.h"
#include "node_tool.h"

#include <limits.h>
#include <string.h>
#include <unistd.h>

static const char help[] =
    "usage: lmbake preview OUT.gltf [--port N] [--lightmap ktx2|hdr]\n"
    "\n"
    "Serves a baked level (the .gltf `lmbake bake` wrote) on http://127.0.0.1:PORT/ and prints\n"
    "the address; open it in a browser. Views: lit, lightmap only, UV1 checker with texel grid,\n"
    "invalid texels, each atlas flat with a texel readout. Nothing is loaded from the internet\n"
    "and only this machine can connect. Ctrl-C stops it.\n"
    "\n"
    "  --port N     port to listen on (default: a free one)\n"
    "  --lightmap ktx2|hdr\n"
    "               which file of each atlas the page reads: its KTX2 when the glTF names one\n"
    "               (the default), or the Radiance .hdr\n"
    "  -h, --help   this help\n";

int cmd_preview(int argc, char **argv)
{
    const char *gltf = NULL, *port = NULL, *source = NULL, *v;
    for (int i = 1; i < argc; i++) {
        int r;
        unsigned long long n;
        if (cli_is_flag(argv[i], "--help", "-h")) {
            fputs(help, stdout);
            return LMB_OK;
        } else if ((r = cli_opt_value(argc, argv, &i, "--port", NULL, &v)) != 0) {
            if (r < 0 || !cli_parse_uint(v, 65535, &n))
                return cli_usage_error("preview", "--port needs a number 0..65535");
            port = v;
        } else if ((r = cli_opt_value(argc, argv, &i, "--lightmap", NULL, &v)) != 0) {
            if (r < 0 || (strcmp(v, "ktx2") != 0 && strcmp(v, "hdr") != 0))
                return cli_usage_error("preview", "--lightmap needs ktx2 or hdr");
            source = v;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            return cli_usage_error("preview", "unknown option '%s'", argv[i]);
        } else if (gltf) {
            return cli_usage_error("preview", "one glTF at a time ('%s' and '%s')", gltf, argv[i]);
        } else {
            gltf = argv[i];
        }
    }
    if (!gltf)
        return cli_usage_error("preview", "no OUT.gltf given (the .gltf that `lmbake bake` wrote)");
    if (access(gltf, R_OK) != 0) {
        lmb_error err;
        lmb_error_set(&err, LMB_ERR_INPUT, "cannot open '%s' for the preview", gltf);
        return cli_fail(&err);
    }
    char script[PATH_MAX + 64];
    if (!node_tool_path("serve.mjs", script, sizeof script))
        return LMB_ERR_INTERNAL;
    char *args[6] = {(char *)gltf, NULL, NULL, NULL, NULL, NULL};
    int n = 1;
    if (port) {
        args[n++] = "--port";
        args[n++] = (char *)port;
    }
    if (source) {
        args[n++] = "--lightmap";
        args[n++] = (char *)source;
    }
    return node_tool_exec(script, args);
}
