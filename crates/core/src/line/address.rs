//! A typed TCP address checked whole: host (or IPv6 in brackets) and a port in range.

/// A TCP address to connect to, as HOST:PORT: a host name or IPv4 address, or an IPv6
/// address in brackets; the port 1-65535, or `default_port` when none is given (else
/// one is required). Nothing is resolved: a name that does not resolve fails when the
/// line opens.
pub fn address(typed: &str, default_port: Option<u16>) -> Result<String, String> {
    let typed = typed.trim();
    let form = if default_port.is_some() {
        "HOST[:PORT]"
    } else {
        "HOST:PORT"
    };
    if typed.is_empty() {
        return Err(format!("no address: name {form}"));
    }
    let (host, port, v6) = if let Some(rest) = typed.strip_prefix('[') {
        let (host, after) = rest
            .split_once(']')
            .ok_or_else(|| format!("`{typed}`: an IPv6 address ends with ]"))?;
        if host.parse::<std::net::Ipv6Addr>().is_err() {
            return Err(format!("`{host}` is not an IPv6 address"));
        }
        let port = match after {
            "" => None,
            p => Some(
                p.strip_prefix(':')
                    .ok_or_else(|| format!("`{typed}`: expected {form}"))?,
            ),
        };
        (host, port, true)
    } else if typed.matches(':').count() > 1 {
        return Err(if typed.parse::<std::net::Ipv6Addr>().is_ok() {
            format!("`{typed}`: put an IPv6 address in brackets, [{typed}]:PORT")
        } else {
            format!("`{typed}` is not an address: expected {form}")
        });
    } else {
        match typed.split_once(':') {
            Some((host, port)) => (host, Some(port), false),
            None => (typed, None, false),
        }
    };
    let name_ok = |c: char| c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_');
    if !v6 && (host.is_empty() || !host.chars().all(name_ok)) {
        return Err(format!(
            "`{typed}` is not an address: expected {form} (a host name or IP address)"
        ));
    }
    let port = match port {
        Some(p) => match p.parse::<u32>() {
            Ok(n) if (1..=65535).contains(&n) => n as u16,
            Ok(n) => return Err(format!("`{typed}`: port {n} is out of range (1-65535)")),
            Err(_) => return Err(format!("`{typed}`: `{p}` is not a port number (1-65535)")),
        },
        None => default_port.ok_or_else(|| format!("`{typed}` names no port: expected {form}"))?,
    };
    Ok(if v6 {
        format!("[{host}]:{port}")
    } else {
        format!("{host}:{port}")
    })
}
