# The fuzz targets and the skybake libraries each one needs; shared by the
# libFuzzer build (CMakeLists.txt here) and the corpus replay in CI
# (the top-level CMakeLists.txt).
set(SKYBAKE_FUZZ_TARGETS mesh_loader ply gltf weights atmosphere rule_spec sky_csv prt_sidecar light image gltf_asset gltf_writer)
set(SKYBAKE_FUZZ_LIBS_mesh_loader skybake::io)
set(SKYBAKE_FUZZ_LIBS_ply skybake::io)
set(SKYBAKE_FUZZ_LIBS_gltf skybake::io)
set(SKYBAKE_FUZZ_LIBS_weights skybake::neural)
set(SKYBAKE_FUZZ_LIBS_atmosphere skybake::sky)
set(SKYBAKE_FUZZ_LIBS_rule_spec skybake::sphere)
set(SKYBAKE_FUZZ_LIBS_sky_csv skybake::sky)
set(SKYBAKE_FUZZ_LIBS_prt_sidecar skybake::prt)
set(SKYBAKE_FUZZ_LIBS_light skybake::prt)
set(SKYBAKE_FUZZ_LIBS_image skybake::io)
set(SKYBAKE_FUZZ_LIBS_gltf_asset skybake::io)
set(SKYBAKE_FUZZ_LIBS_gltf_writer skybake::io)
