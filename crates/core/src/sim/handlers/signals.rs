//! Signal messages (PROTOCOL.md 3.34-3.43): 20BH/20CH/20DH port and flag queries, 24AH/24BH
//! changes, 20EH/20FH/210H variable queries and 24CH/24DH variable changes.

use crate::protocol::{BitChange, BitQuery, Reply, VarData, VarQuery};
use crate::sim::controller::Controller;
use crate::sim::errors::SimError;
use crate::sim::framing::max_command;

impl Controller {
    /// 20BH / 20CH / 20DH: the states asked for, at most what the reply buffer holds
    /// (longer reads are refused A03: the simulator's choice, PROTOCOL.md leaves open
    /// whether a controller cuts them).
    pub(crate) fn msg_bit_query(&mut self, q: &BitQuery) -> Result<Reply, SimError> {
        let max = q.space.max_count(self.cfg.reply_buffer);
        self.signals.read_bits(q, max).map(Reply::Bits)
    }

    /// 24AH output change (held while the I/O interlock is on) and 24BH flag change.
    pub(crate) fn msg_bit_change(&mut self, c: &BitChange) -> Result<(), SimError> {
        self.signals.change_bit(c)
    }

    /// 20EH (its layout inferred, PROTOCOL.md 3.39), 20FH, 210H: values from the
    /// simulator's tables, reals in its [`crate::protocol::RealEncoding`].
    pub(crate) fn msg_var_query(&mut self, q: &VarQuery) -> Result<Reply, SimError> {
        let max = q.kind.max_count(self.cfg.reply_buffer);
        self.signals
            .read_vars(q, self.cfg.real_encoding, max)
            .map(Reply::Vars)
    }

    /// 24CH / 24DH: the whole write checked, then stored; the reply echoes it.
    pub(crate) fn msg_var_write(&mut self, d: &VarData) -> Result<Reply, SimError> {
        let max = d.kind().max_write(max_command(self.cfg.reply_buffer));
        self.signals
            .write_vars(d, self.cfg.real_encoding, max)
            .map(Reply::VarsWritten)
    }
}
