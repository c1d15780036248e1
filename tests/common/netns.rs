//! Two hosts for one test: network namespaces `tc-a-<pid>` and `tc-b-<pid>` joined by one veth
//! pair (`veth-a` 192.0.2.1/24 in A, `veth-b` 192.0.2.2/24 in B; 192.0.2.0/24 is TEST-NET-1,
//! never routed), with `lo` and both veth ends up, a route for `224.0.0.0/4` on the veth in each,
//! no default route and no other interface: nothing else is reachable from either. The drop guard
//! deletes both namespaces (the veth pair goes with them). Creating them needs root (CI runs as
//! root); when that fails the test fails with the reason, it never passes silently.
//!
//! One pair per test process at a time (the names carry the pid): [`TwoHosts::new`] holds a lock
//! until the guard is dropped, so tests in one binary take turns.

use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard};

/// Serialises the tests of one binary: the namespace names carry only the pid.
static ONE_PAIR: Mutex<()> = Mutex::new(());

/// Address of host A (the node's) on the veth.
pub const HOST_A: &str = "192.0.2.1";
/// Address of host B (the peers') on the veth.
pub const HOST_B: &str = "192.0.2.2";

/// The two namespaces; deleted on drop.
pub struct TwoHosts {
    /// Namespace of host A.
    pub a: String,
    /// Namespace of host B.
    pub b: String,
    _turn: MutexGuard<'static, ()>,
}

/// Runs `ip args`; the error names the command and its stderr.
fn ip(args: &[&str]) -> Result<String, String> {
    let out = Command::new("ip").args(args).output().map_err(|e| format!("`ip {}`: cannot run ip: {e}", args.join(" ")))?;
    if out.status.success() {
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    } else {
        Err(format!("`ip {}` failed ({}): {}", args.join(" "), out.status, String::from_utf8_lossy(&out.stderr).trim()))
    }
}

/// Deletes `tc-a-<pid>` / `tc-b-<pid>` namespaces left by test processes that no longer run
/// (a killed test cannot run its guard). Namespaces of live processes are left alone.
fn remove_stale() {
    let Ok(list) = ip(&["netns", "list"]) else { return };
    for name in list.lines().filter_map(|l| l.split_whitespace().next()) {
        let Some(rest) = name.strip_prefix("tc-a-").or_else(|| name.strip_prefix("tc-b-")).or_else(|| name.strip_prefix("tc-l-")) else { continue };
        let pid = rest.split('-').next().unwrap_or_default();
        if pid.parse::<u32>().is_ok() && !std::path::Path::new(&format!("/proc/{pid}")).exists() {
            let _ = ip(&["netns", "del", name]);
        }
    }
}

impl TwoHosts {
    /// Creates the two hosts; panics with the reason when it cannot.
    pub fn new() -> TwoHosts {
        let turn = ONE_PAIR.lock().unwrap_or_else(|e| e.into_inner());
        remove_stale();
        let pid = std::process::id();
        let hosts = TwoHosts { a: format!("tc-a-{pid}"), b: format!("tc-b-{pid}"), _turn: turn };
        if let Err(e) = hosts.build() {
            panic!("cannot create the two test hosts (network namespaces need root; CI runs as root): {e}");
        }
        hosts
    }

    fn build(&self) -> Result<(), String> {
        // Left over from an earlier test of this process that panicked inside `new`: start clean.
        let _ = ip(&["netns", "del", &self.a]);
        let _ = ip(&["netns", "del", &self.b]);
        ip(&["netns", "add", &self.a])?;
        ip(&["netns", "add", &self.b])?;
        // The pair is made inside A with its other end moved straight into B: it never exists in
        // the namespace the test runs in.
        ip(&["-n", &self.a, "link", "add", "veth-a", "type", "veth", "peer", "name", "veth-b", "netns", &self.b])?;
        for (ns, dev, addr) in [(&self.a, "veth-a", HOST_A), (&self.b, "veth-b", HOST_B)] {
            ip(&["-n", ns, "addr", "add", &format!("{addr}/24"), "dev", dev])?;
            ip(&["-n", ns, "link", "set", "lo", "up"])?;
            ip(&["-n", ns, "link", "set", dev, "up"])?;
            ip(&["-n", ns, "route", "add", "224.0.0.0/4", "dev", dev])?;
            // IPv4 only: no IPv6 link-local chatter on the link (best effort).
            let _ = Command::new("ip").args(["netns", "exec", ns, "sysctl", "-q", "-w", "net.ipv6.conf.all.disable_ipv6=1"]).output();
        }
        // Nothing else reachable: no default route, only lo and the veth end.
        for ns in [&self.a, &self.b] {
            let routes = ip(&["-n", ns, "-4", "route", "show", "table", "all"])?;
            if routes.lines().any(|l| l.starts_with("default")) {
                return Err(format!("{ns} has a default route: {routes}"));
            }
            let links = ip(&["-n", ns, "-o", "link", "show"])?;
            let names: Vec<&str> = links.lines().filter_map(|l| l.split(':').nth(1)).map(|n| n.trim().split('@').next().unwrap_or("")).collect();
            if names.len() != 2 || !names.contains(&"lo") {
                return Err(format!("{ns} has interfaces {names:?}, expected lo and its veth end"));
            }
        }
        Ok(())
    }

    /// Multicast off on both veth ends (`ip link set dev <veth> multicast off`) and the multicast
    /// routes removed: discovery can only be by unicast.
    pub fn multicast_off(&self) {
        for (ns, dev) in [(&self.a, "veth-a"), (&self.b, "veth-b")] {
            ip(&["-n", ns, "link", "set", "dev", dev, "multicast", "off"]).unwrap_or_else(|e| panic!("{e}"));
            ip(&["-n", ns, "route", "del", "224.0.0.0/4", "dev", dev]).unwrap_or_else(|e| panic!("{e}"));
            let link = ip(&["-n", ns, "link", "show", "dev", dev]).unwrap_or_else(|e| panic!("{e}"));
            let flags = link.split(['<', '>']).nth(1).unwrap_or("");
            assert!(!flags.split(',').any(|f| f == "MULTICAST"), "{dev} still has multicast: {link}");
            let routes = ip(&["-n", ns, "route", "show", "table", "all"]).unwrap_or_else(|e| panic!("{e}"));
            assert!(!routes.contains("224.0.0.0/4"), "a multicast route is left in {ns}: {routes}");
        }
    }

    /// The wrapper that runs a command in host A: `ip netns exec tc-a-<pid>`.
    pub fn in_a(&self) -> Vec<String> {
        vec!["ip".into(), "netns".into(), "exec".into(), self.a.clone()]
    }

    /// The wrapper that runs a command in host B: `ip netns exec tc-b-<pid>`.
    pub fn in_b(&self) -> Vec<String> {
        vec!["ip".into(), "netns".into(), "exec".into(), self.b.clone()]
    }
}

impl Drop for TwoHosts {
    fn drop(&mut self) {
        for ns in [&self.a, &self.b] {
            if let Err(e) = ip(&["netns", "del", ns]) {
                eprintln!("netns guard: {e}");
            }
        }
    }
}

/// The second address [`LoopbackHost`] puts on `lo` (TEST-NET-2, never routed).
pub const SECOND_ADDRESS: &str = "198.51.100.7";

/// One host with two addresses and no network: namespace `tc-l-<pid>-<n>` whose only interface
/// is `lo`, up, with 127.0.0.1 and [`SECOND_ADDRESS`]/32. A participant bound to the second
/// address is another process of the same host that is not on loopback. Deleted on drop.
pub struct LoopbackHost {
    /// The namespace's name.
    pub ns: String,
}

impl LoopbackHost {
    /// Creates the host; panics with the reason when it cannot (namespaces need root).
    pub fn new() -> LoopbackHost {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        remove_stale();
        let host = LoopbackHost { ns: format!("tc-l-{}-{}", std::process::id(), NEXT.fetch_add(1, Ordering::Relaxed)) };
        let build = || -> Result<(), String> {
            let _ = ip(&["netns", "del", &host.ns]);
            ip(&["netns", "add", &host.ns])?;
            ip(&["-n", &host.ns, "link", "set", "lo", "up"])?;
            ip(&["-n", &host.ns, "addr", "add", &format!("{SECOND_ADDRESS}/32"), "dev", "lo"])?;
            let links = ip(&["-n", &host.ns, "-o", "link", "show"])?;
            if links.lines().count() != 1 {
                return Err(format!("{} has more than lo: {links}", host.ns));
            }
            Ok(())
        };
        if let Err(e) = build() {
            panic!("cannot create the test host (network namespaces need root; CI runs as root): {e}");
        }
        host
    }

    /// The wrapper that runs a command in the host: `ip netns exec tc-l-<pid>-<n>`.
    pub fn wrapper(&self) -> Vec<String> {
        vec!["ip".into(), "netns".into(), "exec".into(), self.ns.clone()]
    }

    /// The local addresses (`address:port`) of every UDP socket process `pid` has open in the
    /// host, as `ss -ulnpH` lists them.
    pub fn udp_sockets_of(&self, pid: u32) -> Vec<String> {
        let out = Command::new("ip").args(["netns", "exec", &self.ns, "ss", "-uanpH"]).output().expect("run ss");
        assert!(out.status.success(), "ss failed: {}", String::from_utf8_lossy(&out.stderr));
        let tag = format!("pid={pid},");
        String::from_utf8_lossy(&out.stdout).lines().filter(|l| l.contains(&tag)).filter_map(|l| l.split_whitespace().nth(3).map(str::to_owned)).collect()
    }
}

impl Drop for LoopbackHost {
    fn drop(&mut self) {
        if let Err(e) = ip(&["netns", "del", &self.ns]) {
            eprintln!("netns guard: {e}");
        }
    }
}
