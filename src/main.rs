//! The `raypack` binary; see `raypack --help`.

// Large scenes' BVHs get transparent huge pages, as Embree's do.
#[global_allocator]
static ALLOC: raypack::huge_pages::HugePageAlloc = raypack::huge_pages::HugePageAlloc;

fn main() -> std::process::ExitCode {
    // Trees built one after another reuse warm pages (see the function).
    raypack::huge_pages::keep_freed_memory();
    raypack::cli::main()
}
