# blender_surface.py -- check that Blender imports and renders the surface
# files the SPH simulator writes (PLY or OBJ triangle mesh + OpenVDB level set).
#
# What it does: clears the default scene; imports the mesh (PLY via
# bpy.ops.import_mesh.ply, or OBJ via bpy.ops.import_scene.obj if the first
# argument ends in .obj); imports the .vdb as a Volume object and checks it has
# a grid named "surface"; places the volume beside the mesh (offset along x by
# the mesh's size); rotates both 90 degrees about x (simulator y-up -> Blender
# z-up); gives the mesh a blue water-like Principled BSDF and the volume a
# Principled Volume; adds a camera framing both, a sun and a floor plane;
# renders with Cycles on the CPU (480x270, 16 samples, no denoising) to OUT.png.
# Prints a one-line summary and exits non-zero if an import fails or the grid
# is missing.
#
# Command:
#   blender -b --factory-startup --python-exit-code 1 \
#       --python scripts/blender_surface.py -- MESH.ply VOLUME.vdb OUT.png
#
# Not part of CI: Blender is too heavy for CI (measured on a 2-core CPU machine with
# Blender 3.4.1 Debian: about 9.4 s wall per run, of which about 6 s is the
# Cycles render; the blender + blender-data packages install about 190 MB).

import math
import os
import sys
import time

import bpy
from mathutils import Vector


def fail(msg):
    print("blender_surface: ERROR: " + msg, flush=True)
    sys.exit(1)


def principled(mat):
    """The material's Principled BSDF node, created if use_nodes gave none."""
    nt = mat.node_tree
    for n in nt.nodes:
        if n.type == "BSDF_PRINCIPLED":
            return n
    out = next((n for n in nt.nodes if n.type == "OUTPUT_MATERIAL"), None)
    if out is None:
        out = nt.nodes.new("ShaderNodeOutputMaterial")
    n = nt.nodes.new("ShaderNodeBsdfPrincipled")
    nt.links.new(n.outputs["BSDF"], out.inputs["Surface"])
    return n


def main():
    t0 = time.time()
    argv = sys.argv
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if len(args) != 3:
        fail("usage: blender -b --factory-startup --python-exit-code 1 "
             "--python blender_surface.py -- MESH.ply|MESH.obj VOLUME.vdb OUT.png")
    mesh_path, vdb_path, out_path = (os.path.abspath(a) for a in args)
    for p in (mesh_path, vdb_path):
        if not os.path.isfile(p):
            fail("no such file: " + p)

    # Clear the default scene (cube, camera, light).
    bpy.ops.object.select_all(action="SELECT")
    bpy.ops.object.delete()

    # Mesh import.
    before = set(bpy.data.objects)
    try:
        if mesh_path.lower().endswith(".obj"):
            # Simulator writes y-up already; keep axes as in the file and do
            # the y-up -> z-up rotation ourselves, as for the PLY.
            res = bpy.ops.import_scene.obj(filepath=mesh_path,
                                           axis_forward="Y", axis_up="Z")
        else:
            res = bpy.ops.import_mesh.ply(filepath=mesh_path)
    except Exception as e:  # operator errors raise RuntimeError
        fail("mesh import failed: %s" % e)
    new = [o for o in bpy.data.objects if o not in before and o.type == "MESH"]
    if "FINISHED" not in res or not new:
        fail("mesh import failed: %s" % (res,))
    mesh_obj = new[0]
    nverts = len(mesh_obj.data.vertices)
    nfaces = len(mesh_obj.data.polygons)
    print("blender_surface: mesh %s: %d vertices, %d faces"
          % (mesh_obj.name, nverts, nfaces), flush=True)
    if nverts == 0 or nfaces == 0:
        fail("mesh is empty")

    # Volume import.
    before = set(bpy.data.objects)
    try:
        res = bpy.ops.object.volume_import(filepath=vdb_path)
    except Exception as e:
        fail("volume import failed: %s" % e)
    new = [o for o in bpy.data.objects if o not in before and o.type == "VOLUME"]
    if "FINISHED" not in res or not new:
        fail("volume import failed: %s" % (res,))
    vol_obj = new[0]
    grids = vol_obj.data.grids
    if not grids.load():
        fail("volume grids failed to load: %s" % grids.error_message)
    names = [g.name for g in grids]
    print("blender_surface: volume %s: grids %s (frame file %s)"
          % (vol_obj.name, names, grids.frame_filepath), flush=True)
    for g in grids:
        print("blender_surface:   grid %s type %s channels %d"
              % (g.name, g.data_type, g.channels), flush=True)
    if "surface" not in names:
        fail("volume has no grid named 'surface' (grids: %s)" % names)

    # y-up -> z-up: +90 degrees about x maps simulator +y to Blender +z.
    for o in (mesh_obj, vol_obj):
        o.rotation_euler = (math.radians(90.0), 0.0, 0.0)
    bpy.context.view_layer.update()

    def world_bbox(o):
        pts = [o.matrix_world @ Vector(c) for c in o.bound_box]
        lo = Vector((min(p.x for p in pts), min(p.y for p in pts), min(p.z for p in pts)))
        hi = Vector((max(p.x for p in pts), max(p.y for p in pts), max(p.z for p in pts)))
        return lo, hi

    mlo, mhi = world_bbox(mesh_obj)
    size_x = mhi.x - mlo.x
    # Place the volume beside the mesh along x, with a 10% gap.
    vlo, vhi = world_bbox(vol_obj)
    vol_obj.location.x += (mhi.x - vlo.x) + 0.1 * size_x
    bpy.context.view_layer.update()
    vlo, vhi = world_bbox(vol_obj)
    lo = Vector((min(mlo.x, vlo.x), min(mlo.y, vlo.y), min(mlo.z, vlo.z)))
    hi = Vector((max(mhi.x, vhi.x), max(mhi.y, vhi.y), max(mhi.z, vhi.z)))
    center = (lo + hi) * 0.5
    extent = hi - lo
    print("blender_surface: mesh bbox %s..%s, volume bbox %s..%s"
          % (tuple(round(v, 3) for v in mlo), tuple(round(v, 3) for v in mhi),
             tuple(round(v, 3) for v in vlo), tuple(round(v, 3) for v in vhi)),
          flush=True)

    # Materials.
    water = bpy.data.materials.new("water")
    water.use_nodes = True
    bsdf = principled(water)
    bsdf.inputs["Base Color"].default_value = (0.1, 0.35, 0.9, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.1
    bsdf.inputs["Transmission"].default_value = 0.5
    bsdf.inputs["IOR"].default_value = 1.33
    mesh_obj.data.materials.clear()
    mesh_obj.data.materials.append(water)

    volmat = bpy.data.materials.new("volume")
    volmat.use_nodes = True
    nt = volmat.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    pv = nt.nodes.new("ShaderNodeVolumePrincipled")
    pv.inputs["Color"].default_value = (0.2, 0.5, 1.0, 1.0)
    pv.inputs["Density"].default_value = 50.0
    # A level set is negative inside; use the "surface" grid through a
    # Map Range so that inside (phi < 0) is dense and outside is empty.
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "surface"
    mr = nt.nodes.new("ShaderNodeMapRange")
    mr.inputs["From Min"].default_value = 0.0
    mr.inputs["From Max"].default_value = -0.01
    mr.inputs["To Min"].default_value = 0.0
    mr.inputs["To Max"].default_value = 1.0
    mr.clamp = True
    pv.inputs["Density Attribute"].default_value = ""
    nt.links.new(attr.outputs["Fac"], mr.inputs["Value"])
    math_n = nt.nodes.new("ShaderNodeMath")
    math_n.operation = "MULTIPLY"
    math_n.inputs[1].default_value = 50.0
    nt.links.new(mr.outputs["Result"], math_n.inputs[0])
    nt.links.new(math_n.outputs["Value"], pv.inputs["Density"])
    nt.links.new(pv.outputs["Volume"], out.inputs["Volume"])
    vol_obj.data.materials.clear()
    vol_obj.data.materials.append(volmat)

    # Floor plane just under both objects.
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(center.x, center.y, lo.z - 0.002))
    floor = bpy.context.active_object
    floor.scale = (extent.x * 3.0, max(extent.y, extent.x) * 3.0, 1.0)
    floormat = bpy.data.materials.new("floor")
    floormat.use_nodes = True
    principled(floormat).inputs["Base Color"].default_value = (0.8, 0.8, 0.8, 1.0)
    floor.data.materials.append(floormat)

    # Sun.
    bpy.ops.object.light_add(type="SUN", location=(center.x, center.y, hi.z + 2.0))
    sun = bpy.context.active_object
    sun.rotation_euler = (math.radians(40.0), math.radians(10.0), math.radians(30.0))
    sun.data.energy = 3.0

    # World: soft grey background light.
    world = bpy.data.worlds.new("world") if bpy.context.scene.world is None else bpy.context.scene.world
    bpy.context.scene.world = world
    world.use_nodes = True
    bg = world.node_tree.nodes.get("Background")
    if bg:
        bg.inputs["Color"].default_value = (0.6, 0.65, 0.7, 1.0)
        bg.inputs["Strength"].default_value = 0.8

    # Camera in front (-y), above, looking at the centre; frame both objects.
    cam_data = bpy.data.cameras.new("camera")
    cam_data.lens = 35.0
    cam = bpy.data.objects.new("camera", cam_data)
    bpy.context.scene.collection.objects.link(cam)
    dist = max(extent.x, extent.z * 16.0 / 9.0) * 1.3
    cam.location = center + Vector((0.0, -dist, dist * 0.55))
    direction = center - cam.location
    cam.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.camera = cam

    # Render settings: Cycles on the CPU, small and quick.
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 16
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.render.resolution_x = 480
    scene.render.resolution_y = 270
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = out_path
    bpy.ops.render.render(write_still=True)
    if not os.path.isfile(out_path):
        fail("render did not write " + out_path)

    print("blender_surface: mesh %d vertices %d faces; volume grids %s; wrote %s in %.1f s"
          % (nverts, nfaces, names, out_path, time.time() - t0), flush=True)


try:
    main()
except SystemExit:
    raise
except Exception as e:
    import traceback
    traceback.print_exc()
    fail("unexpected error: %s" % e)
