"""`cmake --install` puts the plugin where ParaView auto-loads it: installs the build into a
fresh prefix, then runs pvbatch with only PV_PLUGIN_PATH, and with only PV_PLUGIN_CONFIG_FILE,
pointing there (InstalledPlugin.py checks the proxies exist without LoadPlugin and work).

  python3 TestInstall.py --cmake cmake --build-dir build --pvbatch pvbatch --workdir DIR
"""

import argparse
import glob
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Modules"))
import rgmc_testing  # noqa: E402


def main():
    parser = argparse.ArgumentParser()
    for name in ("--cmake", "--build-dir", "--pvbatch", "--workdir"):
        parser.add_argument(name, required=True)
    args = parser.parse_args()
    prefix = os.path.join(os.path.abspath(args.workdir), "prefix")
    shutil.rmtree(prefix, ignore_errors=True)
    subprocess.run([args.cmake, "--install", args.build_dir, "--prefix", prefix], check=True)
    plugins = glob.glob(os.path.join(prefix, "**", "RGMarchingCubes.so"), recursive=True)
    configs = glob.glob(os.path.join(prefix, "**", "rgmc.plugins.xml"), recursive=True)
    if len(plugins) != 1 or len(configs) != 1:
        print("FAILED: installed %s and %s" % (plugins, configs), file=sys.stderr)
        return 1
    script = rgmc_testing.in_paraview("InstalledPlugin.py")
    base = {k: v for k, v in os.environ.items() if k not in ("PV_PLUGIN_PATH", "PV_PLUGIN_CONFIG_FILE")}
    failures = 0
    for name, value in (("PV_PLUGIN_PATH", os.path.dirname(plugins[0])), ("PV_PLUGIN_CONFIG_FILE", configs[0])):
        result = subprocess.run([args.pvbatch, script], env=dict(base, **{name: value}),
                                capture_output=True, text=True, timeout=300)
        print("%s=%s: %s%s" % (name, value, result.stdout, result.stderr[-2000:]))
        if result.returncode != 0:
            print("FAILED: with %s the installed plugin did not load or work" % name, file=sys.stderr)
            failures += 1
    return 1 if failures else 0


sys.exit(main())
