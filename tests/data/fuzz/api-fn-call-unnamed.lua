-- fuzz case: an fn called by traj:derive named itself '?' in its error
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
return F["trajectory:derive"](P["rtraj"], H["s_method"], P["fn"])
end
