//! Two "hosts" on one machine: Linux network namespaces joined by veth pairs, for the
//! multi-host tests.
//!
//! * [`Link::Switched`]: one veth pair, one subnet (`10.213.0.1/24` on A, `10.213.0.2/24` on
//!   B), multicast on: a cell network on which multicast flows.
//! * [`Link::Routed`]: A (`10.213.1.1/24`) and B (`10.213.2.1/24`) on two subnets joined by a
//!   third namespace that forwards IPv4 unicast. Multicast is not routed, so it does not
//!   cross: a factory network that blocks it.
//!
//! Each namespace has its loopback up (with multicast). The veth pairs are created inside
//! the namespaces (`ip link add … netns …`), so the host's own interfaces never carry them,
//! and these addresses exist only inside the namespaces. Names carry the process id and a
//! per-process counter, so parallel runs and parallel tests do not collide. [`HostPair`]
//! deletes its namespaces when dropped, also when the test fails; deleting a namespace
//! destroys its veth ends and with them the pairs.
//!
//! Code runs "on a host" by running on a thread that first joins that namespace
//! ([`HostPair::spawn_on`], [`HostPair::on`]): a network namespace is a per-thread attribute
//! (`setns(2)`), inherited by the threads that thread starts. Every socket a DDS participant
//! opens on such a thread (and on the threads it starts: RustDDS's event loop and discovery)
//! is in that namespace, so a node started there sees only that host's interfaces: `lo` and
//! its veth end.
//!
//! Creating namespaces needs root (`CAP_SYS_ADMIN`, `CAP_NET_ADMIN`) and `ip` (iproute2).
//! Without them [`HostPair::create`] fails the test with the reason, unless
//! `KERF_SKIP_NETNS=1` is set: then it returns `None` and the test prints that it skipped.

use std::{
    net::Ipv4Addr,
    os::fd::AsRawFd,
    process::Command,
    sync::atomic::{AtomicU32, Ordering},
    thread::JoinHandle,
};

/// One of the two hosts of a [`HostPair`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Host {
    /// The first host.
    A,
    /// The second host.
    B,
}

/// How the two hosts are connected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Link {
    /// One veth pair, one subnet, multicast flows.
    Switched,
    /// Two subnets joined by a router namespace: unicast is forwarded, multicast is not.
    Routed,
}

/// Two network namespaces (and a router namespace for [`Link::Routed`]) joined by veth
/// pairs; deleted on drop.
pub struct HostPair {
    link: Link,
    /// Namespaces: A, B, router.
    names: [String; 3],
    /// Namespaces created so far (deleted on drop).
    created: Vec<String>,
}

/// Counts the pairs this process created, for unique names.
static PAIRS: AtomicU32 = AtomicU32::new(0);

/// The variable that turns a missing namespace permission into a skip.
pub const SKIP_VAR: &str = "KERF_SKIP_NETNS";

impl HostPair {
    /// The private address of `host`.
    pub fn address(&self, host: Host) -> Ipv4Addr {
        match (self.link, host) {
            (Link::Switched, Host::A) => Ipv4Addr::new(10, 213, 0, 1),
            (Link::Switched, Host::B) => Ipv4Addr::new(10, 213, 0, 2),
            (Link::Routed, Host::A) => Ipv4Addr::new(10, 213, 1, 1),
            (Link::Routed, Host::B) => Ipv4Addr::new(10, 213, 2, 1),
        }
    }

    /// Creates the namespaces and the veth pairs between them.
    ///
    /// # Returns
    /// The pair, or `None` when namespaces cannot be created and `KERF_SKIP_NETNS=1` is set.
    /// Without that variable a failure fails the test, naming the command and its error.
    pub fn create(link: Link) -> Option<Self> {
        let n = PAIRS.fetch_add(1, Ordering::Relaxed);
        let pid = std::process::id();
        let mut pair = HostPair {
            link,
            names: ["a", "b", "r"].map(|side| format!("kerf-{pid}-{n}-{side}")),
            created: Vec::new(),
        };
        match pair.set_up(&format!("kv{pid}x{n}")) {
            Ok(()) => Some(pair),
            Err(e) if std::env::var(SKIP_VAR).as_deref() == Ok("1") => {
                println!(
                    "SKIPPED: {SKIP_VAR}=1 is set and network namespaces are unavailable: {e}"
                );
                None
            }
            Err(e) => panic!(
                "cannot create the test's network namespaces ({e}); the multi-host tests need \
                 root and iproute2's `ip`. Set {SKIP_VAR}=1 to skip them."
            ),
        }
    }

    /// Creates the namespaces and links; `tag` prefixes the interface names, which have at
    /// most 15 bytes ("kv" + pid (≤ 7 digits) + "x" + n + 2).
    fn set_up(&mut self, tag: &str) -> Result<(), String> {
        let hosts = match self.link {
            Link::Switched => 2,
            Link::Routed => 3,
        };
        for name in self.names[..hosts].iter().cloned() {
            ip(&["netns", "add", &name])?;
            self.created.push(name);
        }
        let [na, nb, nr] = self.names.clone();
        let (va, vb) = (format!("{tag}a"), format!("{tag}b"));
        // Every end is born inside its namespace: the host never has it.
        let pair = |x: &str, nx: &str, y: &str, ny: &str| {
            ip(&[
                "link", "add", "name", x, "netns", nx, "type", "veth", "peer", "name", y, "netns",
                ny,
            ])
        };
        let up = |ns: &str, dev: &str, addr: &str| -> Result<(), String> {
            ip(&["-n", ns, "addr", "add", addr, "dev", dev])?;
            ip(&["-n", ns, "link", "set", dev, "multicast", "on"])?;
            ip(&["-n", ns, "link", "set", dev, "up"])?;
            Ok(())
        };
        for ns in &self.names[..hosts] {
            ip(&["-n", ns, "link", "set", "lo", "up"])?;
            ip(&["-n", ns, "link", "set", "lo", "multicast", "on"])?;
        }
        match self.link {
            Link::Switched => {
                pair(&va, &na, &vb, &nb)?;
                up(&na, &va, "10.213.0.1/24")?;
                up(&nb, &vb, "10.213.0.2/24")?;
            }
            Link::Routed => {
                let (ra, rb) = (format!("{tag}ra"), format!("{tag}rb"));
                pair(&va, &na, &ra, &nr)?;
                pair(&vb, &nb, &rb, &nr)?;
                up(&na, &va, "10.213.1.1/24")?;
                up(&nb, &vb, "10.213.2.1/24")?;
                up(&nr, &ra, "10.213.1.254/24")?;
                up(&nr, &rb, "10.213.2.254/24")?;
                ip(&["-n", &na, "route", "add", "default", "via", "10.213.1.254"])?;
                ip(&["-n", &nb, "route", "add", "default", "via", "10.213.2.254"])?;
                // Forwarding in the router namespace only (a per-namespace setting).
                ip(&[
                    "netns",
                    "exec",
                    &nr,
                    "sh",
                    "-c",
                    "echo 1 > /proc/sys/net/ipv4/ip_forward",
                ])?;
            }
        }
        Ok(())
    }

    /// The namespace name of `host` (`ip netns exec NAME …` enters it).
    pub fn name(&self, host: Host) -> &str {
        match host {
            Host::A => &self.names[0],
            Host::B => &self.names[1],
        }
    }

    /// Runs `f` on a new thread inside `host`'s namespace; the thread and every thread it
    /// starts have only that host's network. Join the handle for `f`'s result.
    pub fn spawn_on<T: Send + 'static>(
        &self,
        host: Host,
        f: impl FnOnce() -> T + Send + 'static,
    ) -> JoinHandle<T> {
        let path = format!("/run/netns/{}", self.name(host));
        std::thread::spawn(move || {
            enter(&path);
            f()
        })
    }

    /// Runs `f` inside `host`'s namespace (on a thread of its own) and returns its result; a
    /// panic in `f` is a panic here.
    pub fn on<T: Send + 'static>(&self, host: Host, f: impl FnOnce() -> T + Send + 'static) -> T {
        match self.spawn_on(host, f).join() {
            Ok(t) => t,
            Err(panic) => std::panic::resume_unwind(panic),
        }
    }

    /// `ip -n NAMESPACE args…` in `host`'s namespace; its stdout, or the error.
    pub fn ip_on(&self, host: Host, args: &[&str]) -> Result<String, String> {
        let mut all = vec!["-n", self.name(host)];
        all.extend_from_slice(args);
        ip(&all)
    }
}

impl Drop for HostPair {
    fn drop(&mut self) {
        for name in &self.created {
            // The namespace lives on while a socket or thread still uses it, then goes with
            // its veth end; the name is removed at once.
            if let Err(e) = ip(&["netns", "delete", name]) {
                eprintln!("warning: could not delete network namespace {name}: {e}");
            }
        }
    }
}

/// Moves the calling thread into the network namespace bound at `path`; panics with the
/// reason if it cannot.
fn enter(path: &str) {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("open {path}: {e}"));
    // SAFETY: `file` is an open namespace file; setns only changes this thread's namespace.
    let r = unsafe { libc::setns(file.as_raw_fd(), libc::CLONE_NEWNET) };
    assert!(r == 0, "setns({path}): {}", std::io::Error::last_os_error());
}

/// Runs `ip args…`; its stdout, or an error with the command and its stderr.
fn ip(args: &[&str]) -> Result<String, String> {
    let out = Command::new("ip")
        .args(args)
        .output()
        .map_err(|e| format!("cannot run `ip {}`: {e}", args.join(" ")))?;
    if out.status.success() {
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    } else {
        Err(format!(
            "`ip {}` failed ({}): {}",
            args.join(" "),
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        ))
    }
}
