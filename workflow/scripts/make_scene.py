"""One run's scene: the case's scene with the setting's JSON merge patch (RFC 7386) applied, its input paths
made absolute so that the scene may live in the run's own folder. Called by the Snakefile's `scene` rule."""
import json
import os


def merge_patch(target, patch):
    """RFC 7386: objects merge key by key, null removes a key, anything else replaces. Written here because
    Debian 12 packages no RFC 7386 library (python3-jsonpatch is RFC 6902, a list of operations), and the
    whole rule is these lines. Note that a setting's null removes the scene's key, so the run takes pneumo's
    default; pneumo itself keeps a scene's null as "off" (docs/scene_reference.md)."""
    if not isinstance(patch, dict):
        return patch
    result = dict(target) if isinstance(target, dict) else {}
    for key, value in patch.items():
        if value is None:
            result.pop(key, None)
        else:
            result[key] = merge_patch(result.get(key), value)
    return result


def absolute_inputs(scene, scene_dir):
    """Every relative path under "inputs" is relative to the scene file's folder (docs/scene_reference.md)."""
    for key, value in scene.get("inputs", {}).items():
        if isinstance(value, str) and value and not os.path.isabs(value):
            scene["inputs"][key] = os.path.abspath(os.path.join(scene_dir, value))
    return scene


def main(source, target, patch):
    with open(source) as f:
        scene = json.load(f)
    scene = absolute_inputs(scene, os.path.dirname(os.path.abspath(source)))
    scene = merge_patch(scene, patch)
    tmp = target + ".tmp"
    with open(tmp, "w") as f:
        json.dump(scene, f, indent=2)
        f.write("\n")
    os.replace(tmp, target)


if __name__ == "__main__" and "snakemake" in globals():
    main(snakemake.input[0], snakemake.output[0], dict(snakemake.params.patch))
