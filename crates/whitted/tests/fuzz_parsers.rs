//! Fuzzing every reader with seeded mutations of the repository's fixtures
//! and of generated inputs: nothing may panic, hang or allocate without
//! bound, and whatever a reader accepts must render. How to run it long is
//! in `docs/testing.md`; the machinery is in `tests/fuzz/`.

mod fuzz;

#[global_allocator]
static ALLOCATOR: fuzz::guard::CappedAllocator = fuzz::guard::CappedAllocator;

#[test]
fn toml_scenes_never_panic() {
    fuzz::fuzz(fuzz::targets::toml(), 0);
}

#[test]
fn nff_scenes_never_panic() {
    fuzz::fuzz(fuzz::targets::nff(), 1);
}

#[test]
fn obj_models_and_material_libraries_never_panic() {
    fuzz::fuzz(fuzz::targets::obj(), 2);
}

#[test]
fn obj_positions_never_panic() {
    fuzz::fuzz(fuzz::targets::obj_positions(), 3);
}

#[test]
fn png_and_jpeg_textures_never_panic() {
    fuzz::fuzz(fuzz::targets::image(), 4);
}

#[test]
fn ray_files_never_panic() {
    fuzz::fuzz(fuzz::targets::ray_files(), 5);
}

#[test]
fn partial_images_never_panic() {
    fuzz::fuzz(fuzz::targets::parts(), 6);
}
