"""Every key that a case under cases/ understands is documented in docs/cases.md."""

import subprocess

from cli_common import Runner, parse_arguments


def main():
    arguments = parse_arguments()
    r = Runner(arguments)
    documented = (r.source / "docs" / "cases.md").read_text()
    for case in sorted((r.source / "cases").rglob("*.yaml")):
        result = subprocess.run([r.coapt, "keys", str(case)], capture_output=True, text=True)
        r.expect(result.returncode == 0, f"coapt keys {case.relative_to(r.source)}", result.stderr)
        keys = [line.split("|")[1].strip() for line in result.stdout.splitlines() if line.startswith("| `")]
        missing = [key for key in keys if key not in documented]
        r.expect(not missing, f"{case.relative_to(r.source)}: all {len(keys)} keys in docs/cases.md", f"missing: {missing}")
    r.finish()


if __name__ == "__main__":
    main()
