//! Instructions executed, counted by callgrind (valgrind), for machines whose
//! hardware counters a process cannot read (virtual machines often do not
//! pass them through): the process runs again under
//! `valgrind --tool=callgrind`, and marks each stretch to count with
//! callgrind's client requests, [`zero_stats`] before and [`dump_stats_at`]
//! after; [`count_this_command`] reads back each stretch's total by its label.
//! Outside valgrind a client request is a few instructions that change
//! nothing.
//!
//! Valgrind has no AVX-512: under it raypack's kernels and Embree's run their
//! AVX2 code, whatever the machine has. Counts do not move with the machine's
//! noise, which is what they are for: a faster kernel told apart from a
//! faster machine.

use std::ffi::{CString, OsString};
use std::path::Path;
use std::process::{Command, Stdio};

/// The environment variable that tells a child run it is the counted one.
const CHILD_VARIABLE: &str = "RAYPACK_CALLGRIND_CHILD";

/// Valgrind's client request codes used here (valgrind.h, callgrind.h).
mod request {
    /// `VG_USERREQ__RUNNING_ON_VALGRIND`.
    pub const RUNNING_ON_VALGRIND: usize = 0x1001;
    /// `VG_USERREQ_TOOL_BASE('C', 'T')`: callgrind's first request.
    const CALLGRIND: usize = (b'C' as usize) << 24 | (b'T' as usize) << 16;
    /// `VG_USERREQ__ZERO_STATS`.
    pub const ZERO_STATS: usize = CALLGRIND + 1;
    /// `VG_USERREQ__DUMP_STATS_AT`.
    pub const DUMP_STATS_AT: usize = CALLGRIND + 3;
}

/// Valgrind's client request `request` with argument `arg`; `default` is the
/// answer outside valgrind.
#[cfg(target_arch = "x86_64")]
#[inline(never)]
fn client_request(default: usize, request: usize, arg: usize) -> usize {
    let block: [usize; 6] = [request, arg, 0, 0, 0, 0];
    let mut answer = default;
    // SAFETY: valgrind's "special instruction" on x86-64: rotations of rdi
    // by 128 bits in all and `xchg rbx, rbx` leave every register as it was;
    // valgrind recognises the sequence, reads the six words at rax and puts
    // its answer in rdx. The block lives until the asm ends.
    unsafe {
        std::arch::asm!(
            "rol rdi, 3",
            "rol rdi, 13",
            "rol rdi, 61",
            "rol rdi, 51",
            "xchg rbx, rbx",
            in("rax") block.as_ptr(),
            inout("rdx") answer,
            options(nostack),
        );
    }
    answer
}

/// No client requests off x86-64: the answer is always `default`.
#[cfg(not(target_arch = "x86_64"))]
fn client_request(default: usize, _request: usize, _arg: usize) -> usize {
    default
}

/// Whether this process runs under valgrind.
pub fn running_under_valgrind() -> bool {
    client_request(0, request::RUNNING_ON_VALGRIND, 0) != 0
}

/// Whether this process is the run under callgrind that [`count_this_command`]
/// started (which counts and reports nothing else).
pub fn is_counting_child() -> bool {
    std::env::var_os(CHILD_VARIABLE).is_some() && running_under_valgrind()
}

/// Reset callgrind's counts: what follows is counted from zero.
pub fn zero_stats() {
    client_request(0, request::ZERO_STATS, 0);
}

/// Write callgrind's counts since the last reset as a dump named `label`
/// (and reset them).
pub fn dump_stats_at(label: &str) {
    let label = CString::new(label.replace('\0', " ")).expect("no NUL left");
    client_request(0, request::DUMP_STATS_AT, label.as_ptr() as usize);
}

/// Why instructions cannot be counted here, if they cannot: valgrind is
/// missing, or the CPU is not one whose client requests raypack makes.
pub fn unavailable() -> Option<String> {
    if !cfg!(target_arch = "x86_64") {
        return Some("callgrind's client requests are made on x86-64 only".into());
    }
    match Command::new("valgrind").arg("--version").output() {
        Ok(out) if out.status.success() => None,
        _ => Some("valgrind is not installed (Debian: apt-get install valgrind)".into()),
    }
}

/// How instructions were counted, for a command's closing line: by
/// callgrind, or n/a for the reason `unavailable` gives ([`unavailable`]).
pub fn counted_how(unavailable: Option<&str>) -> String {
    unavailable.map_or(
        "counted by callgrind, one thread, AVX2 code (valgrind has no AVX-512)".into(),
        |why| format!("n/a, {why}"),
    )
}

/// `count_in_child` with this process's own arguments: the same command
/// again, under callgrind.
pub fn count_this_command() -> anyhow::Result<Vec<(String, u64)>> {
    count_in_child(&std::env::args_os().skip(1).collect::<Vec<_>>())
}

/// The instructions per ray of the dump `label` of `counts`, over `rays` rays.
pub fn per_ray(counts: &[(String, u64)], label: &str, rays: u64) -> Option<f64> {
    let (_, count) = counts.iter().find(|(l, _)| l == label)?;
    Some(*count as f64 / rays.max(1) as f64)
}

/// Run this program again with `args` under callgrind (with
/// [`CHILD_VARIABLE`] set), and return the instructions of each dump it
/// made with [`dump_stats_at`], by label, in the order made.
fn count_in_child(args: &[OsString]) -> anyhow::Result<Vec<(String, u64)>> {
    let dir = tempfile::tempdir()?;
    let out_file = dir.path().join("callgrind.out");
    let exe = std::env::current_exe()?;
    let output = Command::new("valgrind")
        .arg("--tool=callgrind")
        .arg(format!("--callgrind-out-file={}", out_file.display()))
        .arg(&exe)
        .args(args)
        .env(CHILD_VARIABLE, "1")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .output()?;
    anyhow::ensure!(
        output.status.success(),
        "the run under callgrind failed ({}): {}",
        output.status,
        String::from_utf8_lossy(&output.stderr).trim_end()
    );
    let mut dumps = Vec::new();
    for entry in std::fs::read_dir(dir.path())? {
        let path = entry?.path();
        if let Some(dump) = read_dump(&path)? {
            dumps.push(dump);
        }
    }
    // `callgrind.out.N`: the N-th dump; order by N.
    dumps.sort_by_key(|(part, _, _)| *part);
    Ok(dumps
        .into_iter()
        .map(|(_, label, count)| (label, count))
        .collect())
}

/// The part number, label and instruction total of the callgrind dump
/// `path`, None for a dump no client request made (the one at exit).
fn read_dump(path: &Path) -> anyhow::Result<Option<(u64, String, u64)>> {
    let text = std::fs::read_to_string(path)?;
    parse_dump(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// [`read_dump`] of the dump's text.
fn parse_dump(text: &str) -> Result<Option<(u64, String, u64)>, String> {
    let field = |name: &str| {
        text.lines()
            .find_map(|line| line.strip_prefix(name))
            .map(str::trim)
    };
    let Some(label) = field("desc: Trigger: Client Request: ") else {
        return Ok(None);
    };
    let number = |name: &str| -> Result<u64, String> {
        field(name)
            .ok_or_else(|| format!("no `{name}` line"))?
            .split_whitespace()
            .next()
            .and_then(|n| n.parse().ok())
            .ok_or_else(|| format!("`{name}` is not a count"))
    };
    Ok(Some((number("part:")?, label.to_string(), number("totals:")?)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dump_gives_its_part_label_and_total() {
        let dump = "# callgrind format\nversion: 1\ncreator: callgrind-3.19.0\npid: 12\n\
                    cmd:  raypack bench traversal\npart: 3\n\n\ndesc: I1 cache: \n\
                    desc: Timerange: Basic block 10 - 20\ndesc: Trigger: Client Request: 0/raypack/ao/single\n\n\
                    positions: line\nevents: Ir\nsummary: 4500\n\n\nfl=(1) ???\nfn=(1) x\n0 4500\n\ntotals: 4500\n";
        assert_eq!(
            parse_dump(dump),
            Ok(Some((3, "0/raypack/ao/single".to_string(), 4500)))
        );
        // The dump at exit names no client request.
        let at_exit = dump.replace(
            "desc: Trigger: Client Request: 0/raypack/ao/single",
            "desc: Trigger: Program termination",
        );
        assert_eq!(parse_dump(&at_exit), Ok(None));
        let broken = dump.replace("totals: 4500", "totals: many");
        assert!(parse_dump(&broken).unwrap_err().contains("totals"));
    }

    #[test]
    fn outside_valgrind_requests_change_nothing() {
        if running_under_valgrind() {
            return;
        }
        zero_stats();
        dump_stats_at("nothing");
        assert!(!running_under_valgrind());
    }
}
